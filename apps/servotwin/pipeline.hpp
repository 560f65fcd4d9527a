#pragma once
// Compositions shared by several subcommands: loading a program for a machine, interpolating it
// with the machine's CNC settings and running it on the virtual machine.

#include <string>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/machine/axis_config.hpp"
#include "servotwin/machine/simulator.hpp"
#include "servotwin/motion/interpolation.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::cli {

/// Tracking error x_r - x of one axis over a capture, in the capture's length unit.
struct TrackingStats {
  double rms = 0.0;
  double max = 0.0;
};
TrackingStats tracking_stats(const core::AxisTrace& axis);

/// Interpolator limits of a machine's CNC.
motion::InterpolationLimits limits_of(const machine::MachineConfig& machine);

/// The machine axis driven by a program axis, or -1 (matched by name: x, y, z).
int machine_axis_index(const machine::MachineConfig& machine, motion::Axis axis);

/// Start point of a program on this machine (axis homes).
motion::Point machine_start(const machine::MachineConfig& machine);

/// core::InputError naming the program when it moves an axis the machine does not have.
void check_program_axes(const motion::Program& program, const std::string& program_name,
                        const machine::MachineConfig& machine);

/// Commanded positions of every machine axis (machine.axes order): program axes from the
/// trajectory, other axes held at home.
std::vector<std::vector<double>> machine_commands(const machine::MachineConfig& machine,
                                                  const motion::Trajectory& trajectory);

}  // namespace servotwin::cli
