#pragma once
/// \file
/// Commanded-trajectory CSV: `t` and one `<axis>_cmd` column per axis (the command half of a
/// capture file, so it can be fed to any tool that reads captures' commands).

#include <iosfwd>

#include "servotwin/motion/interpolation.hpp"

namespace servotwin::io {

/// Writes the trajectory with numbers that round-trip exactly.
void write_trajectory_csv(std::ostream& out, const motion::Trajectory& trajectory);

}  // namespace servotwin::io
