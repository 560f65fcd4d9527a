// Design rules of catalog C7.4, PID by virtual inertia (C7.5) and de-normalization (catalog §0).
#include <algorithm>
#include <cmath>

#include "checks.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

namespace {

constexpr double kUncontrollableRatio = 1.3;

RatioClass classify(double r) {
  if (r < kUncontrollableRatio) return RatioClass::kUncontrollable;
  if (r < std::sqrt(3.0)) return RatioClass::kUnderdamped;
  if (r <= std::sqrt(5.0)) return RatioClass::kSweetSpot;
  return RatioClass::kSluggish;
}

std::string verdict_text(RatioClass kind) {
  switch (kind) {
    case RatioClass::kUncontrollable:
      return "practically uncontrollable with motor feedback, use passive methods (shaping)";
    case RatioClass::kUnderdamped: return "cannot be damped to xi >= 0.707 by PI (r < sqrt(3))";
    case RatioClass::kSweetSpot: return "PI sweet spot, r ~ 2 gives ~150 % of wz";
    case RatioClass::kSluggish:
      return "PI sluggish (r > sqrt(5)); PID to r_target = 2 (+~45 %) or full order (~200 % of wz)";
  }
  return "";
}

/// Zeros of the PID numerator (Kp s + Ki)(τ s + 1) + Kd s² strictly in the left half-plane.
bool controller_minimum_phase(const PidGains& g) {
  const core::Polynomial num = core::Polynomial{g.kp, g.ki} * core::Polynomial{g.tau, 1.0} +
                               core::Polynomial{g.kd, 0.0, 0.0};
  return num.degree() <= 0 || core::is_hurwitz(num);
}

std::string negative_kd_reason(double kd, double r, double r_target) {
  return "PID by virtual inertia needs Kd = " + detail::show(kd) + " < 0 here (r = " + detail::show(r) +
         " is below the target r = " + detail::show(r_target) +
         "): that is positive acceleration feedback, which destabilizes the loop and risks right-half-plane "
         "zeros";
}

}  // namespace

ResonanceRatioAdvice advise(double r, double zeta_star) {
  detail::require_ratio(r, "r");
  detail::require_positive(zeta_star, "zeta_star", "a damping ratio");
  ResonanceRatioAdvice a;
  a.r = r;
  a.r_full_bandwidth = std::sqrt(4.0 * zeta_star + 1.0);
  a.full_bandwidth = r <= a.r_full_bandwidth;
  a.kind = classify(r);
  a.verdict = verdict_text(a.kind);
  return a;
}

double virtual_inertia_kd(double r, double r_target) {
  detail::require_ratio(r, "r");
  detail::require_ratio(r_target, "r_target");
  return (r * r - 1.0) / (r_target * r_target - 1.0) - 1.0;
}

double default_derivative_time_constant(double r, double omega_star) {
  detail::require_ratio(r, "r");
  detail::require_positive(omega_star, "omega_star", "a bandwidth");
  return 1.0 / std::max(r, 5.0 * omega_star);
}

PidDesign pid_design(const NormalizedPlant& plant, double r_target, double omega_star, double zeta_star, double tau,
                     bool allow_negative_kd) {
  detail::require_pair(omega_star, zeta_star);
  detail::require_non_negative(tau, "tau", "a derivative filter time constant");
  const double kd = virtual_inertia_kd(plant.r, r_target);
  if (kd < 0.0 && !allow_negative_kd)
    throw core::InputError(core::at_field("r_target"), negative_kd_reason(kd, plant.r, r_target) +
                                                           "; use a PI, or allow a negative Kd explicitly "
                                                           "(--allow-negative-kd)");
  const core::TransferFunction model = plant.motor(false);
  const PolePlacement placed = pi_pole_placement(model, omega_star, zeta_star, kd, tau);
  PidDesign d;
  d.gains = {placed.gains.kp, placed.gains.ki, kd, tau, 1.0, 0.0};
  d.r_virtual = r_target;
  d.condition_number = placed.condition_number;
  d.closed_loop_stable = core::is_hurwitz(closed_loop_polynomial(model, d.gains));
  d.controller_minimum_phase = controller_minimum_phase(d.gains);
  if (kd < 0.0) d.warnings.push_back(negative_kd_reason(kd, plant.r, r_target) + " (allowed on request)");
  if (!d.controller_minimum_phase) d.warnings.push_back("the controller has zeros in the right half-plane");
  if (!d.closed_loop_stable) d.warnings.push_back("the closed loop is unstable on the design model");
  return d;
}

PiGains to_physical(const PiGains& n, const NormalizedPlant& p) noexcept {
  return {n.kp * p.motor_inertia * p.omega_z, n.ki * p.motor_inertia * p.omega_z * p.omega_z};
}

PidGains to_physical(const PidGains& n, const NormalizedPlant& p) noexcept {
  const PiGains pi = to_physical(PiGains{n.kp, n.ki}, p);
  return {pi.kp, pi.ki, n.kd * p.motor_inertia, n.tau / p.omega_z, n.wp, n.wd};
}

PiGains to_normalized(const PiGains& g, const NormalizedPlant& p) noexcept {
  return {g.kp / (p.motor_inertia * p.omega_z), g.ki / (p.motor_inertia * p.omega_z * p.omega_z)};
}

PidGains to_normalized(const PidGains& g, const NormalizedPlant& p) noexcept {
  const PiGains pi = to_normalized(PiGains{g.kp, g.ki}, p);
  return {pi.kp, pi.ki, g.kd / p.motor_inertia, g.tau * p.omega_z, g.wp, g.wd};
}

}  // namespace servotwin::tuning
