#include "servotwin/io/trajectory_csv.hpp"

#include <fmt/format.h>
#include <ostream>

#include "number_format.hpp"

namespace servotwin::io {

void write_trajectory_csv(std::ostream& out, const motion::Trajectory& trajectory) {
  fmt::memory_buffer buffer;
  buffer.append(std::string_view("t"));
  for (motion::Axis axis : trajectory.axes) fmt::format_to(std::back_inserter(buffer), ",{}_cmd", motion::axis_name(axis));
  buffer.push_back('\n');
  const int decimals = detail::time_decimals(0.0, trajectory.ts);
  const std::size_t n = trajectory.size();
  for (std::size_t k = 0; k < n; ++k) {
    detail::append_time(buffer, static_cast<double>(k) * trajectory.ts, decimals);
    for (const auto& column : trajectory.positions) fmt::format_to(std::back_inserter(buffer), ",{}", column[k]);
    buffer.push_back('\n');
    detail::write_out_when_full(buffer, out);
  }
  detail::write_out(buffer, out);
}

}  // namespace servotwin::io
