#pragma once
/// \file
/// Discrete-time design of the pole-placement controller with Kalman disturbance observer and
/// ZPETC feedforward (thesis section 3.4.2; Tomizuka 1987 for the ZPETC).
///
/// Design model (sample period ts, computation delay D = 0 or 1 samples), states
///   xi = [x, v, u(k-1) (only when D = 1)],  X = [xi, d]:
///   xi(k+1) = Phi xi(k) + Gamma u(k) - Gamma_d d(k),   d(k+1) = d(k) + w(k),   y(k) = x(k) + n(k),
/// the exact zero-order-hold model of J x'' + B x' = K u - J d (d is a disturbance acceleration,
/// e.g. friction / J). W = var(w)/ts and R = var(n) come from the controller's Kalman settings.
///
/// Control law at sample k (current-estimator form: the reading y(k) is used at once):
///   X_hat(k|k) = X_hat(k|k-1) + M (y(k) - x_hat(k|k-1))
///   u(k) = N x_r*(k) - L xi_hat(k|k) + (J/K) d_hat(k|k)
///   X_hat(k+1|k) = Phi_a X_hat(k|k) + Gamma_a u(k)
/// L places the poles of Phi - Gamma L at exp(s ts) for s = -zeta wn +- j wn sqrt(1 - zeta^2)
/// (the delay state's pole at 0); N gives unit DC gain from x_r* to x. The tracking transfer
/// function is then x/x_r* = N n(z) / A(z) with the plant numerator n(z) = B+ (z - z1) (z1 in
/// (-1, 0), "poorly damped", so B- = z - z1) and A(z) the placed polynomial; the observer poles
/// cancel (separation). The ZPETC
///   x_r*(z)/x_r(z) = A(z) (z^-1 - z1) / (B+ (1 - z1)^2)
/// makes the overall x/x_r = (z - z1)(z^-1 - z1)/(1 - z1)^2: zero phase, unit DC gain. It is an
/// FIR filter reading x_r(k + preview) ... x_r(k - 1), preview = deg A = 2 + D.

#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "servotwin/machine/axis_config.hpp"

namespace servotwin::machine {

/// Solution of the filter-form discrete algebraic Riccati equation
///   P = A P A' - A P C' (C P C' + R)^-1 C P A' + Q
/// (the steady-state a-priori covariance of a Kalman filter), by the structure-preserving
/// doubling algorithm: each iteration squares the Riccati recursion, so it converges
/// quadratically wherever the recursion converges ((A, Q) stabilizable, (A, C) detectable).
struct RiccatiSolution {
  Eigen::MatrixXd P;
  int iterations = 0;
  double residual = 0.0;  ///< max |DARE residual| / max(1, max |P|)
};
/// Throws core::InputError when the recursion does not converge (no stabilizing solution).
RiccatiSolution solve_filter_riccati(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Eigen::MatrixXd& Q,
                                     const Eigen::MatrixXd& R);

/// Everything the pole-placement controller needs, in the plant's units.
struct PolePlacementDesign {
  int delay = 0;                 ///< D, computation delay the design includes
  Eigen::MatrixXd phi;           ///< (2 + D) x (2 + D)
  Eigen::VectorXd gamma;         ///< control input
  Eigen::VectorXd gamma_d;       ///< disturbance-acceleration input (enters with a minus sign)
  Eigen::RowVectorXd feedback;   ///< L
  double reference_gain = 0.0;   ///< N
  /// Augmented estimator model X = [xi, d]: X(k+1) = phi_a X + gamma_a u.
  Eigen::MatrixXd phi_a;
  Eigen::VectorXd gamma_a;
  Eigen::VectorXd kalman_gain;   ///< M (current-estimator form), size 3 + D
  Eigen::MatrixXd covariance;    ///< a-priori steady-state covariance P
  int riccati_iterations = 0;
  double disturbance_gain = 0.0;  ///< J / K: d_hat enters u with this factor
  std::vector<std::complex<double>> controller_poles;  ///< eig(Phi - Gamma L), z-plane
  std::vector<std::complex<double>> observer_poles;    ///< eig(Phi_a - M C Phi_a), z-plane
  std::vector<double> closed_loop_den;  ///< A(z), descending powers, monic, degree 2 + D
  double plant_zero = 0.0;       ///< z1, zero of the zero-order-hold plant
  double plant_numerator_gain = 0.0;  ///< n(z) = plant_numerator_gain (z - z1)
  bool zpetc = false;
  int preview = 0;               ///< command samples read ahead (2 + D with ZPETC, else 0)
  /// FIR taps: x_r*(k) = sum_j zpetc_taps[j] x_r(k + preview - j), j = 0 .. preview + 1.
  std::vector<double> zpetc_taps;
};

/// Designs the controller for `plant` at ts with the given computation delay (0 or 1).
/// Throws core::InputError for a design that cannot be realized (e.g. the Riccati recursion does
/// not converge).
PolePlacementDesign design_pole_placement(const RigidPlant& plant, const PolePlacementController& controller,
                                          double ts, int delay_samples);

}  // namespace servotwin::machine
