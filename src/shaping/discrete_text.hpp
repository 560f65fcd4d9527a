#pragma once
// Numbers in error messages of the discretization, real-time shaper and shaped-path code (the
// shaping library does not link fmt).
#include <cstddef>
#include <cstdio>
#include <string>

namespace servotwin::shaping::discrete_detail {

inline std::string num(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

inline std::string num(std::size_t value) { return std::to_string(value); }

}  // namespace servotwin::shaping::discrete_detail
