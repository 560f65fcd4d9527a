#include "servotwin/core/error.hpp"

#include <algorithm>
#include <utility>

namespace servotwin::core {

SourceLocation at_field(std::string field) {
  SourceLocation where;
  where.field = std::move(field);
  return where;
}

std::string printable(std::string_view text, std::size_t max_chars) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  const std::size_t n = std::min(text.size(), max_chars);
  for (std::size_t i = 0; i < n; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte >= 0x20 && byte < 0x7f) {
      out += static_cast<char>(byte);
    } else {
      out += "\\x";
      out += kHex[byte >> 4U];
      out += kHex[byte & 0xFU];
    }
  }
  if (text.size() > max_chars) out += "...";
  return out;
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
