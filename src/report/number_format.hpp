#pragma once
// Number formatting shared by the reports' tables (internal to the report module).

#include <fmt/format.h>

#include <cmath>
#include <string>

namespace servotwin::report::detail {

/// `significant` significant digits ({:g}); a missing value (NaN) shows as "-", infinities as
/// "+inf" / "-inf", so a table never prints "nan".
inline std::string format_number(double v, int significant) {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return v > 0.0 ? "+inf" : "-inf";
  return fmt::format("{:.{}g}", v, significant);
}

}  // namespace servotwin::report::detail
