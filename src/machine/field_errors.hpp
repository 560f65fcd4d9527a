#pragma once
// Validation messages of the machine module (internal): numbers as people read them and errors
// that name the offending field.
#include <cmath>
#include <sstream>
#include <string>

#include "servotwin/core/error.hpp"

namespace servotwin::machine::detail {

/// A value with 10 significant digits, for messages.
inline std::string number(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

/// core::InputError at `field` (no file: the io layer adds it).
[[noreturn]] inline void fail(const std::string& field, const std::string& message) {
  throw core::InputError(core::at_field(field), message);
}

/// Fails at `field` unless v is finite and > 0.
inline void positive(double v, const std::string& field) {
  if (!std::isfinite(v) || !(v > 0.0)) fail(field, "expected a finite number > 0, found " + number(v));
}

/// Fails at `field` unless v is finite and >= 0.
inline void non_negative(double v, const std::string& field) {
  if (!std::isfinite(v) || v < 0.0) fail(field, "expected a finite number >= 0, found " + number(v));
}

}  // namespace servotwin::machine::detail
