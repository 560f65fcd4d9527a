#pragma once
/// \file
/// The flexible-frame test CSV written by `servotwin simulate --test frame-sequence`
/// (vcnc::simulate_frame_sequence, catalog C7.19):
///
///   # servotwin.frame-sequence/1 ts=0.01 setpoint=1 load_force=0.1 load_step_time=15 stator_force=0.1 stator_step_time=30
///   t,setpoint,rotor_velocity,load_velocity,stator_velocity,frame_velocity,motor_force
///
/// one row per sample t = k·ts. `setpoint` is the (shaped) rotor-velocity setpoint, the rotor and
/// load velocities are in stator coordinates (what the drive's sensors see), the stator and frame
/// velocities absolute; units are the frame's (m/s and N for a linear axis).
#include <ostream>

#include "servotwin/vcnc/frame_sequence.hpp"

namespace servotwin::io {

/// Writes the CSV above for `run` made with `settings`, streaming in 64 KiB chunks.
void write_frame_sequence_csv(std::ostream& out, const vcnc::FrameSequence& run,
                              const vcnc::FrameSequenceSettings& settings);

}  // namespace servotwin::io
