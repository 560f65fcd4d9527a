// Rigid-body tunings (catalog C7.1) and the closed forms of eqs. 7.36 and 7.63 (catalog C7.3).
#include <algorithm>
#include <cmath>
#include <limits>

#include "checks.hpp"
#include "closed_forms.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

namespace {

/// num_p/ω*, num_i/ω*² and den of eq. 7.63 as polynomials in ω* (descending powers).
struct Eq763 {
  core::Polynomial num_p_over_w, num_i_over_w2, den;
};

Eq763 eq763(double r, double zz, double zs) {
  const double r2 = r * r;
  return {core::Polynomial{2.0 * zs, 2.0 * zz * (1.0 - r2) - 8.0 * zz * zs * zs,
                           8.0 * zs * zs * zs + 8.0 * zz * zz * zs * r2 - 4.0 * zs, -8.0 * zs * zs * zz * r2,
                           2.0 * zs * r2},
          core::Polynomial{1.0, -4.0 * zs * zz, 4.0 * zz * zz * r2 - r2 + 4.0 * zs * zs - 1.0, -4.0 * zs * zz * r2, r2},
          core::Polynomial{1.0, -4.0 * zs * zz, -(2.0 - 4.0 * zz * zz - 4.0 * zs * zs), -4.0 * zs * zz, 1.0}};
}

/// Smallest real root of p in (0, 1], or +inf.
double first_root_in_unit_interval(const core::Polynomial& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const std::complex<double>& x : p.roots())
    if (std::abs(x.imag()) <= 1e-12 * std::abs(x) && x.real() > 0.0 && x.real() <= 1.0) best = std::min(best, x.real());
  return best;
}

}  // namespace

PiGains pi_symmetric_optimum(double inertia, double lag_time_constant) {
  detail::require_positive(inertia, "inertia", "an inertia");
  detail::require_positive(lag_time_constant, "lag_time_constant", "a time constant [s]");
  return {inertia / (2.0 * lag_time_constant), inertia / (8.0 * lag_time_constant * lag_time_constant)};
}

PiGains pi_rigid_pole_placement(double inertia, double omega_star, double zeta_star) {
  detail::require_positive(inertia, "inertia", "an inertia");
  detail::require_pair(omega_star, zeta_star);
  return {2.0 * zeta_star * omega_star * inertia, inertia * omega_star * omega_star};
}

PiGains pi_closed_form_undamped(double omega_star, double zeta_star, double r) {
  detail::require_pair(omega_star, zeta_star);
  detail::require_ratio(r, "r");
  const double w = omega_star, z = zeta_star, w2 = w * w, r2 = r * r;
  const double den = w2 * w2 - (2.0 - 4.0 * z * z) * w2 + 1.0;  // (ω*² − 1)² + 4ζ*²ω*² > 0
  const double kp = (2.0 * z * w2 * w2 * w + (8.0 * z * z * z - 4.0 * z) * w2 * w + 2.0 * z * r2 * w) / den;
  const double ki = w2 * (w2 * w2 + (4.0 * z * z - r2 - 1.0) * w2 + r2) / den;
  return {kp, ki};
}

PiGains pi_closed_form_damped(double omega_star, double zeta_star, double r, double zeta_z) {
  detail::require_pair(omega_star, zeta_star);
  detail::require_ratio(r, "r");
  detail::require_non_negative(zeta_z, "zeta_z", "a damping ratio");
  const Eq763 e = eq763(r, zeta_z, zeta_star);
  const double den = e.den(omega_star);
  const double w2 = omega_star * omega_star;
  if (std::abs(den) <= 1e-12 * (1.0 + w2 * w2))
    throw core::InputError(core::at_field("omega_star"),
                           "the assigned pair coincides with the antiresonance zeros (zeta_star = zeta_z = " +
                               detail::show(zeta_z) + ", omega_star = 1): eq. 7.63 has no solution there");
  return {omega_star * e.num_p_over_w(omega_star) / den, w2 * e.num_i_over_w2(omega_star) / den};
}

double frictionless_gain_limit(double r, double zeta_z, double zeta_star) {
  return detail::frictionless_gain_root(r, zeta_z, zeta_star).omega;
}

namespace detail {

GainRoot frictionless_gain_root(double r, double zeta_z, double zeta_star) {
  require_ratio(r, "r");
  require_non_negative(zeta_z, "zeta_z", "a damping ratio");
  require_positive(zeta_star, "zeta_star", "a damping ratio");
  const Eq763 e = eq763(r, zeta_z, zeta_star);
  const double wp = first_root_in_unit_interval(e.num_p_over_w);
  const double wi = first_root_in_unit_interval(e.num_i_over_w2);
  if (std::isinf(wp) && std::isinf(wi)) return {1.0, RangeLimit::kFullBandwidth};
  if (wi <= wp) return {wi, RangeLimit::kIntegralGain};
  return {wp, RangeLimit::kProportionalGain};
}

}  // namespace detail

}  // namespace servotwin::tuning
