#pragma once
/// \file
/// Equivalent closed-loop axis model of thesis Eq. 3.3,
///   [s^2 + a1 s + a2 + a3/s] x = [b0 s^2 + b1 s + b2 + a3/s] x_r - [PV d0 + NV d1],
/// computed from a plant and controller.

#include <complex>
#include <string>
#include <vector>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/machine/axis_config.hpp"

namespace servotwin::machine {

/// Coefficients of Eq. 3.3.
struct ClosedLoopCoefficients {
  double a1 = 0, a2 = 0, a3 = 0, b0 = 0, b1 = 0, b2 = 0, d0 = 0, d1 = 0;
};

/// A linear controller in two-degree-of-freedom PID form (continuous time):
///   u = (r3 s^2 + r2 s + r1 + r0/s) x_r - (c2 s + c1 + c0/s) x.
/// P, PI, PD, PID, P-PI cascade and sliding mode with feedforward all reduce to it. Eq. 3.3 holds
/// exactly when r0 = c0 (the integral acts on the tracking error).
struct TwoDofPid {
  double r3 = 0, r2 = 0, r1 = 0, r0 = 0;
  double c2 = 0, c1 = 0, c0 = 0;
};

/// The general mapping: a1 = (B + K c2)/J, a2 = K c1/J, a3 = K c0/J, b0 = K r3/J, b1 = K r2/J,
/// b2 = K r1/J, d0 = F+/J, d1 = F-/J. Throws core::InputError when r0 != c0 (relative 1e-12).
ClosedLoopCoefficients closed_loop_coefficients(const RigidPlant& plant, const TwoDofPid& law,
                                                const Friction& friction);

/// The equivalent two-DOF law of a PID-form controller (P-PI, PID, sliding mode) in continuous
/// time; throws std::invalid_argument for a pole-placement controller.
TwoDofPid two_dof_law(const Controller& controller, const RigidPlant& plant);

/// Thesis Eq. 3.4 (P-PI, its feedforward convention): u = (Kd + Ki/s)(Kp (x_r + Kv x_r' + Ka x_r'') - Kp x - x').
TwoDofPid thesis_ppi_law(double Kp, double Kd, double Ki, double Kv, double Ka);
/// Thesis Eq. 3.5 (PID): u = Kp e + Ki/s e + Kd s e + Kv x_r' + Ka x_r''.
TwoDofPid thesis_pid_law(double Kp, double Ki, double Kd, double Kv, double Ka);

/// Tracking transfer function x/x_r = (b0 s^3 + b1 s^2 + b2 s + a3)/(s^3 + a1 s^2 + a2 s + a3).
core::TransferFunction tracking_tf(const ClosedLoopCoefficients& c);
/// Disturbance transfer function x/d = -s/(s^3 + a1 s^2 + a2 s + a3), d in friction/J units.
core::TransferFunction disturbance_tf(const ClosedLoopCoefficients& c);

/// Closed loop of one axis as reported by `servotwin machine --json`.
struct EquivalentClosedLoop {
  ClosedLoopCoefficients coefficients;
  /// True when the coefficients are the exact continuous-time closed loop of the controller law
  /// (P-PI, PID, sliding mode). False for the discrete pole-placement controller, whose
  /// coefficients come from `method` below.
  bool exact = true;
  std::string method;  ///< how the coefficients were obtained, for people
  std::vector<core::ModalInfo> poles;  ///< of the tracking transfer function
  std::vector<core::ModalInfo> zeros;
  /// Discrete-time poles/zeros of the sampled loop (z-plane, with ts), always reported.
  std::vector<std::complex<double>> discrete_poles, discrete_zeros;
};

/// Equivalent closed loop of an axis sampled at ts.
EquivalentClosedLoop equivalent_closed_loop(const AxisConfig& axis, double ts);

}  // namespace servotwin::machine
