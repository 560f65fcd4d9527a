#pragma once
/// \file
/// Equivalent closed-loop axis model of thesis Eq. 3.3,
///   [s^2 + a1 s + a2 + a3/s] x = [b0 s^2 + b1 s + b2 + a3/s] x_r - [PV d0 + NV d1],
/// computed from a plant and controller.

#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/state_space.hpp"
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
///  * P-PI:  c2 = kv, c1 = kv kp + ki, c0 = ki kp; r3 = acc_ff, r2 = kv vel_ff,
///           r1 = kv kp + ki vel_ff, r0 = ki kp.
///  * PID:   c2 = kd, c1 = kp, c0 = ki; r3 = acc_ff, r2 = kd + vel_ff, r1 = kp, r0 = ki.
///  * SMC (model Jm, Bm, Km): c2 = Jm lambda/Km + ks, c1 = Bm lambda/Km + ks lambda + rho,
///           c0 = rho lambda; r3 = Jm/Km, r2 = Bm/Km + c2, r1 = c1, r0 = c0. With the model equal
///           to the plant b0 = 1, b1 = a1, b2 = a2 and the characteristic polynomial is
///           (s + lambda)(s^2 + (B + K ks)/J s + K rho/J).
TwoDofPid two_dof_law(const Controller& controller, const RigidPlant& plant);

/// Thesis Eq. 3.4 (P-PI, its feedforward convention): u = (Kd + Ki/s)(Kp (x_r + Kv x_r' + Ka x_r'') - Kp x - x').
TwoDofPid thesis_ppi_law(double Kp, double Kd, double Ki, double Kv, double Ka);
/// Thesis Eq. 3.5 (PID): u = Kp e + Ki/s e + Kd s e + Kv x_r' + Ka x_r''.
TwoDofPid thesis_pid_law(double Kp, double Ki, double Kd, double Kv, double Ka);

/// Tracking transfer function x/x_r = (b0 s^3 + b1 s^2 + b2 s + a3)/(s^3 + a1 s^2 + a2 s + a3).
core::TransferFunction tracking_tf(const ClosedLoopCoefficients& c);
/// Disturbance transfer function x/d = -s/(s^3 + a1 s^2 + a2 s + a3), d in friction/J units.
core::TransferFunction disturbance_tf(const ClosedLoopCoefficients& c);

// ---- the exact sampled closed loop ------------------------------------------------------------

/// Command samples an axis's controller reads ahead: 1 for P-PI, PID and sliding mode (central
/// differences), 2 + delay_samples for pole placement with ZPETC, 0 without.
int command_preview(const AxisConfig& axis);

/// The linear sampled closed loop of one axis (no friction, backlash, saturation or
/// quantization): the exact zero-order-hold plant plus the controller's difference equations.
///   inputs  [x_r(k + preview), d(k)], d a disturbance acceleration held over the sample
///           (the plant is J x'' + B x' = K u - J d, so d = friction / J as in Eq. 3.3);
///   outputs [x(k), u_applied(k)].
/// The first `loop_states` states are plant, delay line and controller; the remaining ones are
/// the command shift register x_r(k-1) ... x_r(k+preview-1) (eigenvalues 0, no feedback).
/// With zero state and commands that start at 0, core::simulate of this system equals
/// machine::simulate in ideal mode (with `include_delay`, the axis's delay_samples kept).
struct DiscreteClosedLoop {
  core::DiscreteStateSpace system;
  int preview = 0;
  Eigen::Index loop_states = 0;
};
DiscreteClosedLoop discrete_closed_loop(const AxisConfig& axis, double ts, bool include_delay = false);

/// A discrete transfer function num(z)/den(z) (descending powers) with sample period ts.
struct DiscreteTransferFunction {
  core::Polynomial num, den;
  double ts = 0.0;
  /// Value at z = exp(j omega ts).
  [[nodiscard]] std::complex<double> frequency_response(double omega_rad_s) const noexcept;
};

/// Tracking transfer function x(z)/x_r(z) of the sampled loop with the axis's delay, the command
/// preview included (so it may be non-causal: deg num > deg den is possible). Derived in
/// polynomial form, independently of `discrete_closed_loop`:
///  * P-PI / PID / sliding mode: u = (R(z) x_r - S(z) y) / (ts^2 z (z - 1)), plant
///    n(z)/(a(z) z^D) => x/x_r = n R / (a z^D ts^2 z (z-1) + n S);
///  * pole placement: N n(z) F(z) / A(z) (separation; F = ZPETC or 1), not cancelled, so the
///    thesis's Table 4.2 poles 0.86846 +- j0.11762 and zero -0.99937 appear as such.
DiscreteTransferFunction discrete_tracking_tf(const AxisConfig& axis, double ts);

/// Least-squares fit of Eq. 3.3's continuous tracking and disturbance responses to the exact
/// sampled loop's frequency responses (tracking z^preview C(zI-A)^-1 B_r, disturbance from a
/// held disturbance acceleration) at z = exp(j omega ts), on `points` log-spaced frequencies
/// from f_min_hz to f_max_hz (default a quarter of the Nyquist frequency). Equation error
/// D(s) G - N(s) = 0 weighted by 1/|D_prev(s)| (Sanathanan-Koerner iterations, so the
/// converged fit minimizes the output error of the tracking response and the relative error of
/// the disturbance response), columns scaled, solved by QR.
struct EquivalentFit {
  ClosedLoopCoefficients coefficients;
  double f_min_hz = 0.0, f_max_hz = 0.0;
  int points = 0;
  int iterations = 0;
  double max_tracking_error = 0.0;      ///< max |T_fit - T| on the grid
  double max_disturbance_error = 0.0;   ///< max |G_fit - G| / |G| on the grid
};
EquivalentFit fit_equivalent_coefficients(const AxisConfig& axis, double ts, double f_max_hz = 0.0,
                                          double f_min_hz = 0.1, int points = 200);

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
  /// Discrete-time poles/zeros of the sampled loop's tracking transfer function
  /// (discrete_tracking_tf: z-plane, with ts, command preview included), always reported.
  std::vector<std::complex<double>> discrete_poles, discrete_zeros;
  int preview = 0;  ///< command samples read ahead
  std::optional<EquivalentFit> fit;  ///< set when exact == false
};

/// Equivalent closed loop of an axis sampled at ts.
EquivalentClosedLoop equivalent_closed_loop(const AxisConfig& axis, double ts);

}  // namespace servotwin::machine
