#include "servotwin/io/drive_simulation_csv.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iterator>

#include "number_format.hpp"

namespace servotwin::io {

namespace {

/// A value, or an empty cell for a signal the plant does not have (NaN).
template <typename Buffer>
void append_cell(Buffer& buffer, double v) {
  if (std::isnan(v)) fmt::format_to(std::back_inserter(buffer), ",");
  else fmt::format_to(std::back_inserter(buffer), ",{}", v);
}

}  // namespace

void write_drive_simulation_csv(std::ostream& out, const vcnc::DriveSimulation& sim) {
  fmt::memory_buffer buffer;
  auto it = std::back_inserter(buffer);
  fmt::format_to(it, "# servotwin.drive-simulation/1 test={} structure={} ts={} amplitude={}\n", vcnc::to_string(sim.test),
                 tuning::to_string(sim.structure), sim.ts, sim.amplitude);
  fmt::format_to(it,
                 "t,reference,load_torque,torque,motor_velocity,load_velocity,motor_position,load_position,measured,"
                 "linear_torque,linear_motor_velocity,linear_load_velocity,linear_motor_position,linear_load_position\n");
  const int decimals = detail::time_decimals(0.0, sim.ts);
  for (std::size_t k = 0; k < sim.samples.size(); ++k) {
    const vcnc::DriveSample& s = sim.samples[k];
    const vcnc::DriveSample& l = sim.linear_samples[k];
    detail::append_time(buffer, s.t, decimals);
    for (const double v : {s.reference, s.load_torque, s.torque_command, s.motor_velocity, s.load_velocity,
                           s.motor_position, s.load_position, s.measured, l.torque_command, l.motor_velocity,
                           l.load_velocity, l.motor_position, l.load_position})
      append_cell(buffer, v);
    fmt::format_to(it, "\n");
    detail::write_out_when_full(buffer, out);
  }
  detail::write_out(buffer, out);
}

}  // namespace servotwin::io
