#include "servotwin/core/error.hpp"

#include <utility>

namespace servotwin::core {

SourceLocation at_field(std::string field) {
  SourceLocation where;
  where.field = std::move(field);
  return where;
}

// Built with append() rather than operator+ chains: GCC 12 reports a false -Wrestrict on the
// latter (GCC bug 105329).
std::string to_string(const SourceLocation& where) {
  std::string out = where.file;
  if (where.line > 0) {
    out.append(out.empty() ? "line " : ":").append(std::to_string(where.line));
    if (where.column > 0) out.append(":").append(std::to_string(where.column));
  }
  if (!where.field.empty()) {
    if (!out.empty()) out.append(" ");
    out.append("(").append(where.field).append(")");
  }
  return out;
}

namespace {
std::string compose(const SourceLocation& where, const std::string& message) {
  std::string out = to_string(where);
  if (!out.empty()) out.append(": ");
  return out.append(message);
}
}  // namespace

InputError::InputError(SourceLocation where, const std::string& message)
    : std::runtime_error(compose(where, message)), where_(std::move(where)), reason_(message) {}

InputError::InputError(const std::string& message) : std::runtime_error(message), reason_(message) {}

}  // namespace servotwin::core
