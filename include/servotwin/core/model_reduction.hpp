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
/// Unstable or marginally stable systems (e.g. a two-mass plant's rigid-body mode, or an
/// H-infinity controller with its integrator and unstable poles) have no Gramians:
/// balanced_truncation_stable_part() splits off the poles right of a boundary alpha, reduces the
/// rest and keeps them beside it, as Octave's btamodred (SLICOT AB09MD) does.

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
  /// States kept unreduced because their poles lie right of the boundary (only
  /// balanced_truncation_stable_part; 0 otherwise). `hankel` then belongs to the stable part.
  Eigen::Index unstable_states = 0;
};

/// An additive decomposition G = Gs + Gu: Gs has the poles with Re < alpha and G's feedthrough, Gu
/// the others and no feedthrough.
struct StableSplit {
  StateSpace stable;
  StateSpace unstable;
};

/// The decomposition above, through an ordered complex Schur form (a real orthonormal basis of the
/// invariant subspace of the poles left of alpha) and one Sylvester equation that decouples the two
/// blocks. Throws std::invalid_argument for inconsistent shapes or non-finite matrices,
/// std::domain_error when the two pole sets are too close to be separated (the Sylvester
/// equation is singular to working precision).
StableSplit stable_split(const StateSpace& sys, double alpha = 0.0);

/// Balanced truncation to `order` states (0 <= order <= states). Errors as
/// hankel_singular_values, and std::invalid_argument for an order out of range.
BalancedTruncation balanced_truncation(const StateSpace& sys, Eigen::Index order);

/// Default stability boundary of balanced_truncation_stable_part(): Octave's btamodred default
/// -sqrt(eps), so an integrator (pole at 0) counts as unstable and is kept.
inline constexpr double kStableBoundary = -1.4901161193847656e-08;

/// Balanced truncation of the part of `sys` with poles left of alpha (stable_split), the rest kept:
/// the result has `order` states, of which unstable_states are the kept ones. Throws as
/// stable_split, and std::invalid_argument when `order` is below the number of kept states or
/// above the system's.
BalancedTruncation balanced_truncation_stable_part(const StateSpace& sys, Eigen::Index order,
                                                   double alpha = kStableBoundary);
/// The same on a split already made (a caller that also needs the split's parts, e.g. to check
/// the order against the unstable states first).
BalancedTruncation balanced_truncation_stable_part(const StableSplit& split, Eigen::Index order);

}  // namespace servotwin::core
