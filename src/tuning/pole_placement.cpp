// Numeric partial pole placement (catalog C7.3 "numerical equivalent") and the second
// pair by exact division.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "checks.hpp"
#include "placement.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

namespace {

using core::Polynomial;

constexpr double kMaxCondition = 1e12;
constexpr double kSecondPairTolerance = 1e-6;

/// Remainder s1·σ + s0 of p(ωσ) modulo σ² + 2ζσ + 1 (the assigned pair on the axis scaled by ω;
/// for ζ <= 1 its roots have modulus 1, so the Horner recursion neither grows nor shrinks).
struct Remainder {
  double s1 = 0.0, s0 = 0.0;
};

Remainder scaled_remainder(const Polynomial& p, double omega, double zeta) {
  const std::span<const double> c = p.coefficients();
  double power = std::pow(omega, static_cast<double>(c.size()) - 1.0);
  Remainder r;
  for (double coefficient : c) {
    // R ← R·σ + c_k ω^k, with σ² ≡ −2ζσ − 1.
    const double s1 = r.s0 - 2.0 * zeta * r.s1;
    r.s0 = coefficient * power - r.s1;
    r.s1 = s1;
    power /= omega;
  }
  return r;
}

/// Σ |p_k| ω^k: the size of p's terms on the scaled axis (|σ| = 1), against which its remainder is
/// judged.
double scaled_magnitude(const Polynomial& p, double omega) {
  double m = 0.0;
  for (double coefficient : p.coefficients()) m = m * omega + std::abs(coefficient);
  return m;
}

/// Roots of s² + b s + c, cancellation-free; a complex pair upper member first, real roots by
/// ascending modulus.
std::array<std::complex<double>, 2> quadratic_roots(double b, double c) {
  const double disc = b * b - 4.0 * c;
  if (disc < 0.0) {
    const double im = std::sqrt(-disc) / 2.0;
    return {std::complex<double>(-b / 2.0, im), std::complex<double>(-b / 2.0, -im)};
  }
  const double q = -(b + std::copysign(std::sqrt(disc), b)) / 2.0;
  const double x1 = q, x2 = q != 0.0 ? c / q : 0.0;
  return std::abs(x1) <= std::abs(x2) ? std::array<std::complex<double>, 2>{x1, x2}
                                      : std::array<std::complex<double>, 2>{x2, x1};
}

SecondPair pair_from_quadratic(double b, double c) {
  SecondPair p;
  p.roots = quadratic_roots(b, c);
  p.real = p.roots[0].imag() == 0.0;
  p.stable = b > 0.0 && c > 0.0;
  p.omega = c >= 0.0 ? std::sqrt(c) : std::nan("");
  p.zeta = b / (2.0 * p.omega);
  p.min_radius = std::min(std::abs(p.roots[0]), std::abs(p.roots[1]));
  return p;
}

void check_gain_args(double kd, double tau) {
  detail::require_finite(kd, "kd");
  detail::require_non_negative(tau, "tau", "a derivative filter time constant");
}

}  // namespace

namespace detail {

PlacementProblem::PlacementProblem(const core::TransferFunction& plant, double kd, double tau)
    : c0(Polynomial{1.0, 0.0} * Polynomial{tau, 1.0} * plant.den() + Polynomial{kd, 0.0, 0.0} * plant.num()),
      cp(Polynomial{1.0, 0.0} * Polynomial{tau, 1.0} * plant.num()),
      ci(Polynomial{tau, 1.0} * plant.num()) {}

core::Polynomial PlacementProblem::closed_loop(const PiGains& gains) const {
  return c0 + gains.kp * cp + gains.ki * ci;
}

std::optional<PolePlacement> place(const PlacementProblem& problem, double omega, double zeta) {
  const Remainder rp = scaled_remainder(problem.cp, omega, zeta);
  const Remainder ri = scaled_remainder(problem.ci, omega, zeta);
  const Remainder r0 = scaled_remainder(problem.c0, omega, zeta);
  // Columns in units of their polynomials' coefficient magnitude: entries much smaller than 1 are
  // cancellation (the pair sits on plant zeros), which a max-entry scaling would hide.
  const double mp = scaled_magnitude(problem.cp, omega), mi = scaled_magnitude(problem.ci, omega);
  if (!(mp > 0.0) || !(mi > 0.0) || !std::isfinite(mp * mi)) return std::nullopt;
  const Eigen::Matrix2d m{{rp.s1 / mp, ri.s1 / mi}, {rp.s0 / mp, ri.s0 / mi}};
  const Eigen::Vector2d sv = Eigen::JacobiSVD<Eigen::Matrix2d>(m).singularValues();
  const double condition = 1.0 / sv(1);
  if (!(condition <= kMaxCondition)) return std::nullopt;
  const Eigen::Vector2d x = m.fullPivLu().solve(Eigen::Vector2d(-r0.s1, -r0.s0));
  return PolePlacement{{x(0) / mp, x(1) / mi}, condition};
}

std::optional<SecondPair> second_pair_of(const core::Polynomial& c, double omega, double zeta, double tolerance) {
  if (c.degree() != 4) return std::nullopt;
  // Scaled coefficients a_k of c(ωσ), then synthetic division by σ² + 2ζσ + 1.
  std::array<double, 5> a{};
  double power = std::pow(omega, 4.0), scale = 0.0;
  for (std::size_t i = 0; i < 5; ++i, power /= omega) {
    a[i] = c.coefficients()[i] * power;
    scale = std::max(scale, std::abs(a[i]));
  }
  std::array<double, 3> q{};
  for (std::size_t i = 0; i < 3; ++i) {
    q[i] = a[i];
    a[i + 1] -= 2.0 * zeta * q[i];
    a[i + 2] -= q[i];
  }
  if (std::max(std::abs(a[3]), std::abs(a[4])) > tolerance * scale) return std::nullopt;
  // Quotient q0 σ² + q1 σ + q2 in σ = s/ω → monic s² + (ω q1/q0) s + ω² q2/q0.
  return pair_from_quadratic(omega * q[1] / q[0], omega * omega * q[2] / q[0]);
}

}  // namespace detail

PolePlacement pi_pole_placement(const core::TransferFunction& plant, double omega_star, double zeta_star, double kd,
                                double tau) {
  detail::require_pair(omega_star, zeta_star);
  check_gain_args(kd, tau);
  const detail::PlacementProblem problem(plant, kd, tau);
  if (std::max({problem.c0.degree(), problem.cp.degree(), problem.ci.degree()}) < 2)
    throw core::InputError(core::at_field("plant"),
                           "the closed loop has degree < 2: a PI cannot place a pole pair on this plant");
  const std::optional<PolePlacement> result = detail::place(problem, omega_star, zeta_star);
  if (!result)
    throw core::InputError(core::at_field("omega_star"),
                           "the pair s^2 + 2*" + detail::show(zeta_star) + "*" + detail::show(omega_star) + " s + " +
                               detail::show(omega_star) + "^2 cannot be placed: the placement system is singular "
                               "(condition number > 1e12; the pair coincides with plant zeros)");
  return *result;
}

core::Polynomial closed_loop_polynomial(const core::TransferFunction& plant, const PidGains& gains) {
  detail::require_finite(gains.kp, "kp");
  detail::require_finite(gains.ki, "ki");
  check_gain_args(gains.kd, gains.tau);
  return detail::PlacementProblem(plant, gains.kd, gains.tau).closed_loop({gains.kp, gains.ki});
}

SecondPair second_pair(const NormalizedPlant& plant, const PiGains& gains, double omega_star, double zeta_star,
                       double kd) {
  detail::require_pair(omega_star, zeta_star);
  const core::Polynomial c = closed_loop_polynomial(plant.motor(false), {gains.kp, gains.ki, kd, 0.0});
  const std::optional<SecondPair> pair = detail::second_pair_of(c, omega_star, zeta_star, kSecondPairTolerance);
  if (!pair)
    throw core::InputError(core::at_field("gains"), "the gains Kp = " + detail::show(gains.kp) + ", Ki = " +
                                                        detail::show(gains.ki) +
                                                        " do not place the pair at omega_star = " +
                                                        detail::show(omega_star) + ", zeta_star = " +
                                                        detail::show(zeta_star));
  return *pair;
}

}  // namespace servotwin::tuning
