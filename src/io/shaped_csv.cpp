#include "servotwin/io/shaped_csv.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>

#include "number_format.hpp"

namespace servotwin::io {

void write_shaped_csv(std::ostream& out, const ShapedTrajectory& trajectory) {
  fmt::memory_buffer buffer;
  auto it = std::back_inserter(buffer);
  fmt::format_to(it, "t");
  for (const auto& axis : trajectory.axes) fmt::format_to(it, ",{}_cmd", axis);
  for (const auto& axis : trajectory.axes) fmt::format_to(it, ",{}_shaped", axis);
  fmt::format_to(it, ",deviation\n");
  const int decimals = detail::time_decimals(trajectory.t0, trajectory.ts);
  for (std::size_t k = 0; k < trajectory.deviation.size(); ++k) {
    detail::append_time(buffer, trajectory.t0 + static_cast<double>(k) * trajectory.ts, decimals);
    for (const auto& column : trajectory.commanded) fmt::format_to(it, ",{}", column[std::min(k, column.size() - 1)]);
    for (const auto& column : trajectory.shaped) fmt::format_to(it, ",{}", column[k]);
    fmt::format_to(it, ",{}\n", trajectory.deviation[k]);
    detail::write_out_when_full(buffer, out);
  }
  detail::write_out(buffer, out);
}

}  // namespace servotwin::io
