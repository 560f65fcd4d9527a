#include "misfit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace servotwin::fit::detail {

// Only where every point has its std: swept-sine points carry SNR, not std, and weighting them by
// |P|/SNR was tried and moved the backlash and E14 estimates out of their tolerances (the block's
// SNR is the observer's, not the value's), so such a response keeps log-relative weights.
double effective_std(const core::FrequencyPoint& p, core::QualityKind kind) {
  if (kind != core::QualityKind::kThd || !(p.quality > 0.0)) return p.std_dev;
  const double distortion = p.quality * std::abs(p.value);
  return std::sqrt(p.std_dev * p.std_dev + 0.5 * distortion * distortion);
}

double log_residual_weight(const core::FrequencyPoint& p, core::QualityKind kind, bool known_std) {
  // std_dev is the circular complex standard deviation (E|δ|² = σ²), so each of Re and Im of δ/P
  // has standard deviation σ/(√2|P|).
  return known_std ? std::sqrt(2.0) * std::abs(p.value) / effective_std(p, kind) : 1.0;
}

MisfitScale misfit_scale(const Eigen::VectorXd& r, double dof, bool known_std) {
  const auto m = static_cast<double>(r.size() / 2);
  if (dof <= 0.0 || m < 3.0) return {};
  double lag0 = 0.0, lag1 = 0.0;
  for (Eigen::Index k = 0; k < r.size(); ++k) {
    lag0 += r[k] * r[k];
    if (k + 2 < r.size()) lag1 += r[k] * r[k + 2];  // the same part (Re or Im) of the next point
  }
  // A smooth, systematic misfit leaves fewer independent residuals than points: the effective
  // sample size of an AR(1) sequence is m(1 − ρ1)/(1 + ρ1).
  const double rho = lag0 > 0.0 ? std::clamp(lag1 / lag0, 0.0, 0.98) : 0.0;
  const double kappa = (1.0 + rho) / (1.0 - rho);
  const bool correlated = rho > 2.0 / std::sqrt(m);
  if (known_std) {
    const double s = r.squaredNorm() / dof;
    if (!(s > 1.0 + 3.0 * std::sqrt(2.0 / dof))) return {};
    return {s * kappa, fmt::format("standard deviations scaled by {:.3g}: the misfit is {:.3g} times the measured "
                                   "noise (reduced chi-square {:.3g}) and neighbouring residuals correlate "
                                   "(rho {:.2f}), so the noise alone would understate them",
                                   std::sqrt(s * kappa), std::sqrt(s), s, rho)};
  }
  if (!correlated) return {};
  return {kappa, fmt::format("standard deviations scaled by {:.3g}: neighbouring residuals correlate (rho {:.2f}), a "
                             "systematic misfit",
                             std::sqrt(kappa), rho)};
}

double std_of_variance(double variance) { return variance < 0.0 ? 0.0 : std::sqrt(variance); }

Estimate log_estimate(const Eigen::VectorXd& t, const Eigen::MatrixXd& c, Eigen::Index i, double sign) {
  const double v = sign * std::exp(t[i]);
  return {v, std::abs(v) * std_of_variance(c(i, i))};
}

bool better_run(const core::LmResult& run, const core::LmResult& best) {
  if (run.status == core::LmStatus::kInvalidStart) return false;
  if (!std::isfinite(best.cost)) return true;
  if (run.converged() != best.converged()) return run.converged();
  return run.cost < best.cost;
}

}  // namespace servotwin::fit::detail
