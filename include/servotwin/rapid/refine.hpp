#pragma once
/// \file
/// Output-error refinement of an identified axis model: the coefficients of Eq. 3.3 that make the
/// *simulated* position follow the measured one best, within the same pole bounds.
///
/// The thesis's problem (and solver.hpp) minimizes the equation error 1/2 ||y - Phi theta||^2: one
/// step ahead, with the measured x, x', x'' on the right-hand side. What a twin is used for is
/// simulation from the command alone, and the two optima differ wherever the model cannot be
/// exact. On the sliding-mode preset, whose tracking response is within a few percent of 1, the
/// equation-error optimum predicts the tracking error of another program with a 21 % RMS
/// residual, the output-error optimum started from it with 7 % (docs/rapid-identification-study.md).
///
/// Problem: minimize 1/2 sum_k (x_model,k - x_k)^2 over all samples of all records, the model
/// simulated by AxisModel::simulate_into from each record's command (shifted as in the
/// identification) and its first measured position, friction switching included, subject to
/// p in [p_min, p_max], wn in [wn_min, wn_max], zeta in [zeta_min, zeta_max].
///
/// Method: core::levenberg_marquardt (box bounds, QR steps, forward-difference Jacobian: one
/// simulation per parameter) over the unit-free parameters (ln p, ln wn, zeta, b0, b1/a1, b2/a2,
/// d0/(a2 e), d1/(a2 e)) with the current a1, a2 (so that moving the poles moves the zeros with
/// them) and e = RMS measured tracking error, so nothing depends on the length unit. A local
/// method: it refines a good start (the exact solution) and never returns a worse model than its
/// start; coefficients that the start has at exactly 0 (regressors the solver fixed, e.g. friction
/// without direction reversals) stay 0.

#include <span>
#include <string>
#include <vector>

#include "servotwin/rapid/axis_model.hpp"
#include "servotwin/rapid/solver.hpp"

namespace servotwin::rapid {

/// Records (axis_model.hpp's TrackingRecord): one capture of one axis, commanded and measured
/// position, equal lengths (>= 2 samples).
struct RefineOptions {
  int max_iterations = 60;  ///< Levenberg-Marquardt iterations
  /// Stop when an accepted step lowers the cost by less than this fraction.
  double relative_reduction_tolerance = 1e-4;
  /// Stop when the RMS residual is below this fraction of the RMS measured tracking error: a model
  /// that simulates the error to 0.1 % of itself leaves nothing a user could see.
  double residual_floor = 1e-3;
  int command_shift = 0;  ///< as ModelSimulationOptions::command_shift (the identification's shift)
};

struct Refinement {
  ModelCoefficients coefficients;   ///< refined (the start's when nothing better was found)
  double p = 0.0, wn = 0.0, zeta = 0.0;  ///< search variables of the refined poles [rad/s, -]
  /// Bounds holding at the result; multiplier = derivative of the cost along the variable
  /// (pointing into the box; >= 0 at a Kuhn-Tucker point), in cost units per rad/s or per unit zeta.
  std::vector<ActiveBound> active;
  double initial_cost = 0.0;  ///< 1/2 sum (x_model - x)^2 of the start [length^2]
  double cost = 0.0;          ///< of the result
  int iterations = 0;
  int simulations = 0;        ///< model simulations over all records (Jacobians included)
  bool converged = false;     ///< a convergence test held (false: iteration limit or stall)
  std::string stop_reason;
  double time_ms = 0.0;
};

/// Refines `start` (poles within `bounds`) on the records. core::InputError for no records,
/// records of different command/actual lengths or shorter than 2 samples, non-finite samples,
/// invalid bounds, or a start whose poles cannot be written as (s + p)(s^2 + 2 zeta wn s + wn^2)
/// within the bounds (field "start").
Refinement refine_output_error(const ModelCoefficients& start, double ts, std::span<const TrackingRecord> records,
                               const Bounds& bounds, const RefineOptions& options = {});

}  // namespace servotwin::rapid
