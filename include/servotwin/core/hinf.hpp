#pragma once
/// \file
/// H-infinity output-feedback synthesis for a continuous generalized plant (catalog C2.6): the
/// central controller for a given gamma and the gamma-iteration (bisection) towards the optimum.
/// It is the solver behind the mixed-sensitivity designs of tuning (C7.14–C7.17); GNU Octave's
/// control package (`hinfsyn`, SLICOT SB10FD/SB10AD) is its reference in the tests.
///
/// Generalized plant P with inputs [w; u] and outputs [z; y] (u the last `controls` inputs, y the
/// last `measurements` outputs):
///   x' = A x + B1 w + B2 u,   z = C1 x + D11 w + D12 u,   y = C2 x + D21 w + D22 u.
/// The controller u = K y (positive feedback, as core::lft_lower and Octave's lft) makes the closed
/// loop Tzw = F_l(P, K); synthesis finds K with Tzw internally stable and ||Tzw||_inf < gamma.
///
/// Method: the general (D11 != 0) state-space solution of Glover and Doyle (1988), in the form of
/// Zhou, Doyle & Glover, "Robust and Optimal Control" (1996), Theorem 17.1. D12 and D21 are first
/// brought to [0; I] and [0 I] by orthogonal transformations of z and w (which keep every norm)
/// and scalings of u and y (undone in K); D22 is removed by K = K~ (I + D22 K~)^-1. For a gamma:
///   R  = D1.^T D1. - diag(gamma^2 I, 0),  D1. = [D11 D12];  R~ = D.1 D.1^T - diag(gamma^2 I, 0),
///   D.1 = [D11; D21]; X = the stabilizing solution of the control Riccati equation of
///   [A B; C1 D1.] with weight R^-1, Y the dual one (core::solve_care_indefinite).
/// A controller with ||Tzw|| < gamma exists iff gamma exceeds the norms of the parts of D11 no
/// controller can touch, X and Y exist and are positive semidefinite, and rho(X Y) < gamma^2.
/// The central controller (free parameter Q = 0) is returned; it is unique for the gamma, whatever
/// realization of P is used, which is what makes Octave's controller a reference for ours.
///
/// Assumptions (else std::invalid_argument with the reason): D12 has full column rank and D21
/// full row rank (a "singular" problem: weight the control signal and add measurement noise);
/// (A, B2) stabilizable and (C2, A) detectable, and no invariant zeros of [A B2; C1 D12] or of
/// [A B1; C2 D21] on the imaginary axis (the Riccati equations then have no stabilizing solution
/// for any gamma, which synthesis reports as std::domain_error).

#include <optional>

#include "servotwin/core/state_space.hpp"

namespace servotwin::core {

/// The controller for one gamma and the facts behind it.
struct HinfController {
  StateSpace controller;      ///< K: inputs y, outputs u
  double gamma = 0.0;         ///< the gamma it was built for (||Tzw||_inf < gamma)
  double x_norm = 0.0;        ///< ||X||_2 of the control Riccati solution (grows towards the optimum)
  double y_norm = 0.0;        ///< ||Y||_2 of the filter Riccati solution
  double spectral_radius = 0.0;  ///< rho(X Y) (< gamma^2)
};

/// Central H-infinity controller for `gamma`, or std::nullopt when no stabilizing controller
/// achieves ||Tzw||_inf < gamma: one of the existence conditions fails, or the controller built
/// does not give a stable closed loop with ||Tzw||_inf < gamma (1 + 1e-6) (checked with
/// hinf_norm; the slack is the rounding of controllers within 1e-4 of the optimum). `measurements` and
/// `controls` count y and u (both >= 1, leaving at least one z and one w). Throws
/// std::invalid_argument for shapes, non-finite data, gamma not finite and > 0, or a rank-deficient
/// D12 / D21.
[[nodiscard]] std::optional<HinfController> hinf_central_controller(const StateSpace& plant, Eigen::Index measurements,
                                                                    Eigen::Index controls, double gamma);

/// Settings of the gamma-iteration.
struct HinfOptions {
  double relative_tolerance = 1e-4;  ///< stop when gamma_feasible / gamma_infeasible < 1 + tol
  /// The controller is built for gamma_optimal * backoff (>= 1): at the optimum the central
  /// controller's poles run off to infinity (I - Y X / gamma^2 turns singular), a little back-off
  /// gives a well-conditioned controller at almost the same performance (Octave recommends the
  /// suboptimal controller for the same reason).
  double backoff = 1.0;
  double gamma_max = 1e12;  ///< give up (std::domain_error) when even this gamma is infeasible
};

/// Result of the gamma-iteration.
struct HinfSynthesis {
  HinfController design;         ///< the central controller at gamma_optimal * backoff
  double gamma_optimal = 0.0;    ///< smallest feasible gamma found (within relative_tolerance of the optimum)
  double gamma_infeasible = 0.0; ///< largest gamma proven infeasible (0 when the lower bound is 0)
  double closed_loop_norm = 0.0; ///< ||F_l(P, K)||_inf of the returned controller (hinf_norm)
  int iterations = 0;            ///< central-controller attempts
};

/// Bisection on gamma (geometric, between an infeasible and a feasible value, starting from the
/// lower bound given by D11) until they are within options.relative_tolerance. While the bracket
/// is wider than 1 % a gamma counts as feasible when the existence conditions hold; within it,
/// when the central controller's closed loop is stable and meets gamma (hinf_norm, 1e-6 slack):
/// in floating point the conditions can pass a little below the optimum. gamma_optimal is the
/// smallest gamma so verified (raised from the bisection's end if needed); the controller is the
/// one at gamma_optimal * backoff, verified the same way, balanced (core::balance_states). Throws std::invalid_argument as hinf_central_controller or for options
/// out of range (tolerance in [1e-10, 0.5], backoff in [1, 10], gamma_max > 0); std::domain_error
/// when no gamma up to gamma_max is feasible (e.g. an unstabilizable plant).
[[nodiscard]] HinfSynthesis hinf_synthesis(const StateSpace& plant, Eigen::Index measurements, Eigen::Index controls,
                                           const HinfOptions& options = {});

}  // namespace servotwin::core
