#include "servotwin/vcnc/machine_run.hpp"

#include <algorithm>
#include <cmath>

#include "servotwin/core/error.hpp"

namespace servotwin::vcnc {

motion::InterpolationLimits limits_of(const machine::MachineConfig& machine) {
  motion::InterpolationLimits limits;
  limits.ts = machine.ts;
  limits.accel = machine.cnc.accel;
  limits.jerk = machine.cnc.jerk;
  limits.rapid_feed_mm_min = machine.cnc.rapid_feed_mm_min;
  limits.corner_angle_deg = machine.cnc.corner_angle_deg;
  limits.exact_stop_every_block = machine.cnc.exact_stop_every_block;
  return limits;
}

int machine_axis_index(const machine::MachineConfig& machine, motion::Axis axis) {
  for (std::size_t i = 0; i < machine.axes.size(); ++i)
    if (machine.axes[i].name == motion::axis_name(axis)) return static_cast<int>(i);
  return -1;
}

std::vector<motion::Axis> program_axes_of(const machine::MachineConfig& machine) {
  std::vector<motion::Axis> axes;
  for (std::size_t i = 0; i < motion::kAxisCount; ++i)
    if (machine_axis_index(machine, static_cast<motion::Axis>(i)) >= 0) axes.push_back(static_cast<motion::Axis>(i));
  return axes;
}

motion::Point machine_start(const machine::MachineConfig& machine) {
  motion::Point start{};
  for (std::size_t i = 0; i < motion::kAxisCount; ++i) {
    const int index = machine_axis_index(machine, static_cast<motion::Axis>(i));
    if (index >= 0) start[i] = machine.axes[static_cast<std::size_t>(index)].home;
  }
  return start;
}

void check_program_axes(const motion::Program& program, const std::string& program_name,
                        const machine::MachineConfig& machine) {
  const std::uint8_t used = program.used_axes();
  for (std::size_t i = 0; i < motion::kAxisCount; ++i) {
    const auto axis = static_cast<motion::Axis>(i);
    if ((used & motion::axis_bit(axis)) == 0 || machine_axis_index(machine, axis) >= 0) continue;
    std::string names;
    for (const auto& a : machine.axes) names += (names.empty() ? "" : ", ") + a.name;
    throw core::InputError({program_name, 0, 0, ""},
                           std::string("the program moves axis ") + motion::axis_letter(axis) + " but machine '" +
                               machine.name + "' has only " + names);
  }
}

std::vector<std::vector<double>> machine_commands(const machine::MachineConfig& machine,
                                                  const motion::Trajectory& trajectory) {
  std::vector<std::vector<double>> commands;
  commands.reserve(machine.axes.size());
  for (const auto& axis : machine.axes) {
    std::vector<double> column(trajectory.size(), axis.home);
    for (std::size_t j = 0; j < trajectory.axes.size(); ++j)
      if (axis.name == motion::axis_name(trajectory.axes[j])) column = trajectory.positions[j];
    commands.push_back(std::move(column));
  }
  return commands;
}

core::Capture run_program(const machine::MachineConfig& machine, const motion::Program& program,
                          const machine::SimulationOptions& options) {
  check_program_axes(program, program.name, machine);
  const motion::Trajectory trajectory = motion::interpolate(program, limits_of(machine), program_axes_of(machine));
  return machine::simulate(machine, machine_commands(machine, trajectory), options);
}

TrackingStats tracking_stats(const core::AxisTrace& axis) {
  TrackingStats s;
  double sum = 0.0;
  for (std::size_t k = 0; k < axis.cmd.size(); ++k) {
    const double e = axis.cmd[k] - axis.act[k];
    sum += e * e;
    s.max = std::max(s.max, std::abs(e));
  }
  s.rms = axis.cmd.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(axis.cmd.size()));
  return s;
}

}  // namespace servotwin::vcnc
