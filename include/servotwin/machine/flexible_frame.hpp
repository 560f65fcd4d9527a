#pragma once
/// \file
/// The flexible-frame four-mass model of the dissertation (seed2 catalog C7.18, Sec. 7.6): a
/// machine frame m1 tied to the ground (k1, b1), the actuator's stator m2 mounted on the frame
/// (k2, b2), and the moving part, a rotor m3 coupled to a load m4 (k3, b3). The motor force Fm
/// acts between stator and rotor (+Fm on the rotor, -Fm on the stator); the disturbances are Fl on
/// the load and Fs on the stator (both taken positive along the motion). The sensors sit on the
/// stator, so they measure the rotor and load motion relative to it ("stator coordinates").
///
/// The dissertation prints only the transfer function from Fm to the measured rotor velocity
/// (eq. 7.172), P = Pm + Pf with
///   Pm = (m4 s^2 + b3 s + k3) / (s (m4 m3 s^2 + b3 (m3 + m4) s + k3 (m3 + m4)))   (rotor + load)
///   Pf = s (m1 s^2 + (b1 + b2) s + k1 + k2) / (m2 m1 s^4 + (m2 (b1 + b2) + b2 m1) s^3
///        + (k2 (m2 + m1) + b2 b1 + m2 k1) s^2 + (k2 b1 + b2 k1) s + k2 k1)           (stator + frame)
/// Its state space (eq. 7.171) is missing (catalog: [U]); the one here is written from Newton's law
/// for the four masses and checked against eq. 7.172 in the tests. The sum has one rigid-body
/// integrator and three modes (one of the load, two of the frame): the tuner treats it as a
/// generic three-mode plant (dissertation: "all the previously mentioned methods ... can be used").
///
/// Units: SI, linear (kg, N/m, N s/m, N, m/s); the rotary equivalents work unchanged.

#include <string_view>

#include "servotwin/core/state_space.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace servotwin::machine {

/// The four masses, springs and dampers (dissertation symbols in brackets).
struct FlexibleFrame {
  double frame_mass = 0.0;          ///< m1 > 0
  double frame_stiffness = 0.0;     ///< k1 > 0: frame to ground
  double frame_damping = 0.0;       ///< b1 >= 0
  double stator_mass = 0.0;         ///< m2 > 0
  double mount_stiffness = 0.0;     ///< k2 > 0: stator to frame (the actuator mounting)
  double mount_damping = 0.0;       ///< b2 >= 0
  double rotor_mass = 0.0;          ///< m3 > 0
  double coupling_stiffness = 0.0;  ///< k3 > 0: rotor to load
  double coupling_damping = 0.0;    ///< b3 >= 0
  double load_mass = 0.0;           ///< m4 > 0
};

/// Checks every field (finite; masses and stiffnesses > 0, dampings >= 0); throws core::InputError
/// naming the field (`prefix` + "frame_mass", ...).
void validate(const FlexibleFrame& frame, std::string_view prefix = "");

/// The example of C7.19 (eq. 7.175): m1 = 70, k1 = 4500, b1 = 0.01, m2 = 0.2, k2 = 5, b2 = 0.02,
/// m3 = 0.1, k3 = 0.1, b3 = 0.01, and m4 = 0.2, which the dissertation does not print: it is the
/// value that reproduces every printed frequency of eq. 7.176 (catalog E34).
[[nodiscard]] FlexibleFrame c7_19_flexible_frame() noexcept;

/// Input and output indices of flexible_frame_state_space.
enum FrameInput : Eigen::Index { kMotorForce = 0, kLoadForce = 1, kStatorForce = 2 };
enum FrameOutput : Eigen::Index {
  kRotorVelocity = 0,  ///< v3 - v2: the rotor in stator coordinates (the motor encoder)
  kLoadVelocity = 1,   ///< v4 - v2: the load in stator coordinates
  kRotorPosition = 2,  ///< x3 - x2
  kLoadPosition = 3,   ///< x4 - x2
  kStatorVelocity = 4, ///< v2, absolute
  kFrameVelocity = 5   ///< v1, absolute
};

/// Linear state space: states [x1, v1, x2, v2, x3, v3, x4, v4] (absolute), inputs
/// [Fm, Fl, Fs] (FrameInput), outputs as FrameOutput, D = 0. The rotor-load pair floats, so A has
/// a double eigenvalue at 0 (its position is not observable from a velocity: a minimal velocity
/// transfer function has one integrator). Throws core::InputError as validate().
[[nodiscard]] core::StateSpace flexible_frame_state_space(const FlexibleFrame& frame);

/// Outputs of flexible_frame_velocity_state_space.
enum FrameVelocityOutput : Eigen::Index {
  kRotorVelocityOut = 0,   ///< v3 - v2
  kLoadVelocityOut = 1,    ///< v4 - v2
  kStatorVelocityOut = 2,  ///< v2
  kFrameVelocityOut = 3    ///< v1
};

/// The same dynamics for velocity loops: states [x1, v1, x2, v2, x3 - x4, v3, v4] (the floating
/// pair's common position, which no velocity depends on, removed), inputs [Fm, Fl, Fs], outputs as
/// FrameVelocityOutput, D = 0. Every eigenvalue but the rigid-body one at 0 is stable, so a closed
/// loop on it is stable exactly when its A is Hurwitz. Throws core::InputError as validate().
[[nodiscard]] core::StateSpace flexible_frame_velocity_state_space(const FlexibleFrame& frame);

/// Eq. 7.172: the rotor velocity in stator coordinates per motor force, Pm + Pf over the common
/// denominator (7 poles: the integrator and three modes; 6 zeros). Throws core::InputError as
/// validate().
[[nodiscard]] core::TransferFunction flexible_frame_transfer_function(const FlexibleFrame& frame);

}  // namespace servotwin::machine
