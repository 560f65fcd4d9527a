#pragma once
/// \file
/// The test of the dissertation's flexible-frame example (catalog C7.19, Fig. 7.43): a velocity
/// controller closes the loop on the rotor velocity of machine::FlexibleFrame (measured in stator
/// coordinates), and the run holds a rotor-velocity setpoint step at t = 0, a step of the load
/// force Fl at t = 15 and a step of the stator force Fs at t = 30. What it shows is which modes a
/// design damps: the load mode (seen in the rotor and load velocities) and the frame modes (seen in
/// the stator's absolute velocity), from the setpoint and from disturbances at either end.
///
/// The loop is linear and continuous (the controller as designed, physical units): the closed loop
/// is discretized exactly (zero-order hold) at `ts` for the piecewise-constant inputs, so the
/// samples are exact. The setpoint may be shaped: a step through an input shaper is a staircase
/// (amplitudes A_i at times t_i, each rounded up to the sample grid), C7.19's second design.

#include <array>
#include <complex>
#include <string>
#include <vector>

#include "servotwin/core/state_space.hpp"
#include "servotwin/machine/flexible_frame.hpp"

namespace servotwin::vcnc {

/// The run. Forces act along the motion (+x) on the load (Fl) and on the stator (Fs).
struct FrameSequenceSettings {
  double setpoint = 1.0;           ///< rotor-velocity step at t = 0 (finite, != 0)
  double load_force = 0.1;         ///< Fl step (finite)
  double stator_force = 0.1;       ///< Fs step (finite)
  double load_step_time = 15.0;    ///< [s] > 0
  double stator_step_time = 30.0;  ///< [s] > load_step_time
  double duration = 45.0;          ///< [s] > stator_step_time
  double ts = 0.01;                ///< sample period [s] > 0, at most 10^7 samples
  double residual_window = 5.0;    ///< [s] the end of each phase over which the residual vibration is measured (> 0, shorter than every phase)
  /// Setpoint shaper as impulse times [s] (increasing, first 0) and amplitudes (sum 1); empty: a
  /// plain step.
  std::vector<double> shaper_times, shaper_amplitudes;
};

/// One oscillatory closed-loop mode as an event excites it: the amplitude of its damped sinusoid
/// in each velocity once the event's input has become constant (t = the event, or the shaped
/// setpoint's last impulse), from the modal decomposition of the closed loop
/// (x - x_ss = sum_i v_i w_i^T (x - x_ss), amplitude 2 |c v_i w_i^T (x - x_ss)| for a pair).
struct FrameMode {
  std::complex<double> pole;  ///< closed-loop pole (Im > 0) [rad/s]
  double damping = 0.0;       ///< -Re p/|p|
  double rotor = 0.0, load = 0.0, stator = 0.0;  ///< amplitudes in the rotor, load and stator velocities
};

/// One phase of the run: [start, end) after the setpoint step, the load step or the stator step.
struct FramePhase {
  std::string name;                ///< "setpoint", "load force", "stator force"
  double start = 0.0, end = 0.0;   ///< [s]
  double peak_stator = 0.0;        ///< max |v2| in the phase: how hard the frame is shaken
  double residual_stator = 0.0;    ///< RMS of v2 over the last residual_window: frame ringing left
  double residual_rotor = 0.0;     ///< RMS of (rotor velocity - setpoint) over the same window
  std::vector<FrameMode> modes;    ///< the oscillatory closed-loop modes, ascending |p|, as this event excites them
  /// The setpoint phase: the rotor's overshoot, max(rotor - setpoint)/setpoint (>= 0); the
  /// disturbance phases: max |rotor velocity - setpoint|, the disturbance's peak effect.
  double peak_rotor_error = 0.0;
};

/// The sampled run and its phases.
struct FrameSequence {
  double ts = 0.0;
  std::vector<double> time, setpoint, rotor_velocity, load_velocity, stator_velocity, frame_velocity, motor_force;
  std::array<FramePhase, 3> phases;
  std::vector<std::complex<double>> closed_loop_poles;  ///< eig of the closed loop (the rigid position removed)
  double min_damping = 0.0;  ///< smallest damping ratio among them
};

/// Runs the sequence for `controller` (physical units, inputs [setpoint, rotor velocity], output the
/// motor force: tuning::controller_state_space of a tuned controller) on `frame`. Throws
/// core::InputError naming the field of an invalid setting, frame parameter or controller shape,
/// and std::domain_error (with the poles) when the closed loop is unstable: an unstable run shows
/// nothing about damping.
[[nodiscard]] FrameSequence simulate_frame_sequence(const machine::FlexibleFrame& frame,
                                                    const core::StateSpace& controller,
                                                    const FrameSequenceSettings& settings = {});

/// The closed loop of `controller` around the frame: inputs [setpoint, Fl, Fs], outputs [rotor,
/// load, stator, frame velocity, motor force]; states the frame's 7 (velocity realization) then the
/// controller's. Errors as simulate_frame_sequence, without the stability check.
[[nodiscard]] core::StateSpace frame_closed_loop(const machine::FlexibleFrame& frame, const core::StateSpace& controller);

}  // namespace servotwin::vcnc
