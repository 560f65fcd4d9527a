#pragma once
// Internal to the fit module: the weighting and the misfit rule shared by the linear fit (fit.cpp)
// and the two-mass fit with Coulomb friction (friction_fit.cpp), so that both report standard
// deviations by the same documented rule (FitResult::uncertainty_scale, issue 25 §2).

#include <Eigen/Dense>
#include <cstddef>
#include <string>

#include "servotwin/core/frequency_response.hpp"
#include "servotwin/core/levenberg_marquardt.hpp"
#include "servotwin/fit/fit.hpp"

namespace servotwin::fit::detail {

/// The standard deviation a point is weighted with: its measured one, inflated by its harmonic
/// distortion on a swept-sine response (issue 25 §1): a point with THD q carries harmonics of q
/// times the fundamental, the mark of a nonlinearity (friction, backlash) whose describing function
/// departs from the linear plant by that order, so σ_eff² = σ² + (q|P|)²/2 (the distortion counted
/// as one more circular error of relative size q/√2). Noise-free THD (q ≈ 0) leaves σ as measured.
double effective_std(const core::FrequencyPoint& p, core::QualityKind kind);

/// The weight of a point's complex log residual: √2|P|/σ_eff when `known_std` (Re and Im of the
/// log error then have unit variance), else 1.
double log_residual_weight(const core::FrequencyPoint& p, core::QualityKind kind, bool known_std);

/// The covariance factor of FitResult::uncertainty_scale and why it is not 1 (empty when it is).
/// `r` stacks (Re, Im) of the weighted log residuals of `r.size()/2` points in frequency order;
/// `dof` = 2m − p.
struct MisfitScale {
  double factor = 1.0;
  std::string note;
};
MisfitScale misfit_scale(const Eigen::VectorXd& r, double dof, bool known_std);

/// The standard deviation of a variance: a slightly negative one (rounding) is 0, a NaN one (a
/// singular covariance: not identifiable) stays NaN, so that the output says "unknown", not "exact".
double std_of_variance(double variance);

/// A positive parameter fitted by its logarithm θi: sign·exp(θi) and its std by the delta method,
/// |value|·sqrt(c_ii).
Estimate log_estimate(const Eigen::VectorXd& t, const Eigen::MatrixXd& c, Eigen::Index i, double sign = 1.0);

/// Which of two LM runs from different starts to keep: a converged run beats one that is not,
/// then the lower cost wins; a run that could not start never wins (`best` may be a
/// default-constructed result with infinite cost, meaning none yet).
bool better_run(const core::LmResult& run, const core::LmResult& best);

}  // namespace servotwin::fit::detail
