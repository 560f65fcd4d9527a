#pragma once
/// \file
/// The closed-loop simulation CSV written by `servotwin simulate` (vcnc::simulate_drive):
///
///   # servotwin.drive-simulation/1 test=step structure=pi ts=0.000125 amplitude=1
///   t,reference,load_torque,torque,motor_velocity,load_velocity,motor_position,load_position,measured,
///   linear_torque,linear_motor_velocity,linear_load_velocity,linear_motor_position,linear_load_position
///
/// one row per controller sample t = k·ts (plant units: rad/s, rad, N m for a rotary plant).
/// `reference` is ω* (pi, pid) or φ* (pi+p); `torque` the torque command after the limit;
/// `measured` the plant's measured output (noise and quantization included); the `linear_` columns
/// are the same loop on the plant's linear part. Signals a plant does not have (the load of a
/// transfer-function plant) are empty cells. The leading `#` lines (comments for CSV readers)
/// repeat the run's settings.
#include <ostream>

#include "servotwin/vcnc/drive_simulation.hpp"

namespace servotwin::io {

/// Writes the CSV above, streaming in 64 KiB chunks.
void write_drive_simulation_csv(std::ostream& out, const vcnc::DriveSimulation& simulation);

}  // namespace servotwin::io
