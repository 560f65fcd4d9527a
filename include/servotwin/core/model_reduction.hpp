#pragma once
/// \file
/// Balanced truncation of stable continuous-time systems (Moore; square-root method of Tombs and
/// Laub): the model reduction that C7.16 uses to keep a multi-mode plant or controller small.
///
/// The Gramians come from core::solve_lyapunov; each is factored as P = L L^T by its symmetric
/// eigendecomposition (eigenvalues below rounding clipped to zero), which, unlike a Cholesky
/// factor, also works when a Gramian is only semidefinite (uncontrollable or unobservable states:
/// their Hankel singular values are 0). The SVD of Lo^T Lc gives the Hankel singular values and
/// the projections; only the retained directions are inverted, so nothing is divided by a tiny
/// singular value. Checked against GNU Octave's control package (hsvd, btamodred with the
/// square-root method) by tools/reference/model_reduction_reference.m.
///
/// Unstable or marginally stable systems (e.g. a two-mass plant's rigid-body mode) have no
/// Gramians: reduce the stable part and keep the rest beside it, as Octave's btamodred does.

#include <Eigen/Dense>

#include "servotwin/core/state_space.hpp"

namespace servotwin::core {

/// Hankel singular values of a stable system, descending. Throws std::invalid_argument for
/// inconsistent shapes or non-finite matrices, std::domain_error when A has an eigenvalue with
/// Re >= 0.
Eigen::VectorXd hankel_singular_values(const StateSpace& sys);

struct BalancedTruncation {
  StateSpace reduced;       ///< the balanced realization truncated to `order` states (D unchanged)
  Eigen::VectorXd hankel;   ///< all Hankel singular values of the original, descending
  /// 2 * (sum of the discarded Hankel singular values, each distinct value counted once):
  /// ||G - G_reduced||_inf <= error_bound (Glover; Enns).
  double error_bound = 0.0;
};

/// Balanced truncation to `order` states (0 <= order <= states). Errors as
/// hankel_singular_values, and std::invalid_argument for an order out of range.
BalancedTruncation balanced_truncation(const StateSpace& sys, Eigen::Index order);

}  // namespace servotwin::core
