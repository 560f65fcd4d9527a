#include "servotwin/core/error.hpp"

namespace servotwin::core {

std::string to_string(const SourceLocation& where) {
  std::string out = where.file;
  if (where.line > 0) {
    out += (out.empty() ? "line " : ":") + std::to_string(where.line);
    if (where.column > 0) out += ":" + std::to_string(where.column);
  }
  if (!where.field.empty()) out += (out.empty() ? "" : " ") + std::string("(") + where.field + ")";
  return out;
}

namespace {
std::string compose(const SourceLocation& where, const std::string& message) {
  const std::string prefix = to_string(where);
  return prefix.empty() ? message : prefix + ": " + message;
}
}  // namespace

InputError::InputError(SourceLocation where, const std::string& message)
    : std::runtime_error(compose(where, message)), where_(std::move(where)), reason_(message) {}

InputError::InputError(const std::string& message) : std::runtime_error(message), reason_(message) {}

}  // namespace servotwin::core
