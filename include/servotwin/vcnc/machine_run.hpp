#pragma once
/// \file
/// The virtual CNC: part programs run on virtual machines. Maps a machine's CNC settings to the
/// interpolator, matches program axes to machine axes by name (x, y, z) and simulates the machine
/// on the interpolated commands, producing the capture a real controller's scope would record.

#include <string>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/machine/axis_config.hpp"
#include "servotwin/machine/simulator.hpp"
#include "servotwin/motion/interpolation.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::vcnc {

/// Interpolator limits of a machine's CNC (ts, accel, jerk, rapid feed, corner angle, exact stop).
motion::InterpolationLimits limits_of(const machine::MachineConfig& machine);

/// Index of the machine axis a program axis drives (matched by name x, y, z), or -1.
int machine_axis_index(const machine::MachineConfig& machine, motion::Axis axis);

/// Program axes the machine has, in X, Y, Z order.
std::vector<motion::Axis> program_axes_of(const machine::MachineConfig& machine);

/// Start point of a program on this machine: the axes' home positions.
motion::Point machine_start(const machine::MachineConfig& machine);

/// core::InputError naming `program_name` when the program moves an axis the machine lacks.
void check_program_axes(const motion::Program& program, const std::string& program_name,
                        const machine::MachineConfig& machine);

/// Commanded position of every machine axis (machine.axes order): program axes from the
/// trajectory, other axes held at home.
std::vector<std::vector<double>> machine_commands(const machine::MachineConfig& machine,
                                                  const motion::Trajectory& trajectory);

/// Interpolates the program with the machine's CNC settings and simulates the machine on it.
/// The program must have been read with machine_start() as its start point.
core::Capture run_program(const machine::MachineConfig& machine, const motion::Program& program,
                          const machine::SimulationOptions& options = {});

/// Tracking error x_r - x of one axis over a capture, in the capture's length unit.
struct TrackingStats {
  double rms = 0.0;
  double max = 0.0;
};
TrackingStats tracking_stats(const core::AxisTrace& axis);

}  // namespace servotwin::vcnc
