#include "servotwin/tuning/robustness.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "checks.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::tuning {

namespace {

using core::InputError;
using detail::show;

/// Monic quartic s⁴ + c[1]s³ + c[2]s² + c[3]s + c[4] (c[0] = 1).
using Quartic = std::array<double, 5>;

Quartic quartic_of(const PlantParameters& p, const PiGains& g) noexcept {
  const double kkp = p.k * g.kp, kki = p.k * g.ki;
  const double wz = p.omega_z, w = p.omega;
  return {1.0, 2.0 * p.xi * w + p.a + kkp, w * w + 2.0 * p.a * p.xi * w + kki + 2.0 * kkp * p.xi_z * wz,
          p.a * w * w + kkp * wz * wz + 2.0 * kki * p.xi_z * wz, kki * wz * wz};
}

/// Routh first column of a monic quartic, the same operations core::is_hurwitz performs (rows
/// [1 c2 c4], [c1 c3], [b1 c4], [d1], [c4]); no rescaling is needed at quartic size.
bool quartic_hurwitz(const Quartic& c) noexcept {
  if (!(c[1] > 0.0 && c[2] > 0.0 && c[3] > 0.0 && c[4] > 0.0)) return false;
  const double b1 = c[2] - c[3] / c[1];
  if (!(b1 > 0.0)) return false;
  const double d1 = c[3] - c[1] * c[4] / b1;
  return d1 > 0.0;
}

/// Coefficients of c(s + sigma) (Taylor shift by repeated synthetic division).
Quartic shifted(Quartic c, double sigma) noexcept {
  for (int i = 0; i < 4; ++i)
    for (int j = 1; j <= 4 - i; ++j) c[static_cast<std::size_t>(j)] += sigma * c[static_cast<std::size_t>(j - 1)];
  return c;
}

double max_real_part(const core::Polynomial& p) {
  double m = -std::numeric_limits<double>::infinity();
  for (const std::complex<double>& z : p.roots()) m = std::max(m, z.real());
  return m;
}

void check_interval(const Interval& v, const std::string& name, bool positive) {
  detail::require_finite(v.lo, name + ".lo");
  detail::require_finite(v.nominal, name + ".nominal");
  detail::require_finite(v.hi, name + ".hi");
  if (positive)
    detail::require_positive(v.lo, name + ".lo", "a lower bound");
  else
    detail::require_non_negative(v.lo, name + ".lo", "a lower bound");
  if (!(v.lo <= v.nominal))
    throw InputError(core::at_field(name + ".nominal"),
                     "expected lo <= nominal, got lo = " + show(v.lo) + ", nominal = " + show(v.nominal));
  if (!(v.nominal <= v.hi))
    throw InputError(core::at_field(name + ".hi"),
                     "expected nominal <= hi, got nominal = " + show(v.nominal) + ", hi = " + show(v.hi));
}

void check_gains(const PiGains& g) {
  // The coefficient bounds rest on monotonicity, which needs non-negative gains.
  detail::require_non_negative(g.kp, "gains.kp", "a proportional gain Kp");
  detail::require_non_negative(g.ki, "gains.ki", "an integral gain Ki");
}

/// The values of one parameter on the grid (one value for a degenerate interval).
std::vector<double> grid_values(const Interval& v, int n) {
  if (v.lo == v.hi) return {v.lo};
  std::vector<double> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i + 1 < n; ++i) out.push_back(v.lo + (v.hi - v.lo) * i / (n - 1));
  out.push_back(v.hi);  // the vertex exactly, not lo + (hi − lo)
  return out;
}

/// The Kharitonov polynomials of the coefficient bounds (monic quartics, highest power first).
std::array<Quartic, 4> kharitonov_quartics(const Quartic& lo, const Quartic& hi) noexcept {
  return {Quartic{1.0, hi[1], hi[2], lo[3], lo[4]}, Quartic{1.0, lo[1], lo[2], hi[3], hi[4]},
          Quartic{1.0, hi[1], lo[2], lo[3], hi[4]}, Quartic{1.0, lo[1], hi[2], hi[3], lo[4]}};
}

/// Kharitonov verdict only (no rooting, no allocation); plant and gains already validated.
bool kharitonov_robust(const IntervalPlant& plant, const PiGains& gains) noexcept {
  for (const Quartic& q : kharitonov_quartics(quartic_of(plant.lower(), gains), quartic_of(plant.upper(), gains)))
    if (!quartic_hurwitz(q)) return false;
  return true;
}

/// Grid verdict only: stops at the first unstable case and does not track the worst one.
bool grid_all_stable(const IntervalPlant& plant, const PiGains& gains, int n) {
  const std::vector<double> ks = grid_values(plant.k, n), as = grid_values(plant.a, n), xs = grid_values(plant.xi, n),
                            zs = grid_values(plant.xi_z, n), ws = grid_values(plant.omega, n),
                            wzs = grid_values(plant.omega_z, n);
  for (double k : ks)
    for (double a : as)
      for (double xi : xs)
        for (double xz : zs)
          for (double w : ws)
            for (double wz : wzs)
              if (!quartic_hurwitz(quartic_of({k, a, xi, xz, w, wz}, gains))) return false;
  return true;
}

void check_points(int points_per_parameter) {
  if (points_per_parameter < 2 || points_per_parameter > 12)
    throw InputError(core::at_field("points_per_parameter"),
                     "expected 2 to 12 grid points per parameter, got " + std::to_string(points_per_parameter));
}

Interval spread_interval(double nominal, double spread, const std::string& name) {
  if (!std::isfinite(spread) || spread < 0.0 || spread > 1.0)
    throw InputError(core::at_field("spread." + name), "expected a relative spread in [0, 1], got " + show(spread));
  return {nominal * (1.0 - spread), nominal, nominal * (1.0 + spread)};
}

}  // namespace

PlantParameters IntervalPlant::nominal() const noexcept {
  return {k.nominal, a.nominal, xi.nominal, xi_z.nominal, omega.nominal, omega_z.nominal};
}
PlantParameters IntervalPlant::lower() const noexcept { return {k.lo, a.lo, xi.lo, xi_z.lo, omega.lo, omega_z.lo}; }
PlantParameters IntervalPlant::upper() const noexcept { return {k.hi, a.hi, xi.hi, xi_z.hi, omega.hi, omega_z.hi}; }

void validate(const IntervalPlant& p) {
  check_interval(p.k, "k", true);
  check_interval(p.a, "a", false);
  check_interval(p.xi, "xi", false);
  check_interval(p.xi_z, "xi_z", false);
  check_interval(p.omega, "omega", true);
  check_interval(p.omega_z, "omega_z", true);
}

IntervalPlant make_interval_plant(const PlantParameters& n, const PlantParameters& s) {
  IntervalPlant p{spread_interval(n.k, s.k, "k"),
                  spread_interval(n.a, s.a, "a"),
                  spread_interval(n.xi, s.xi, "xi"),
                  spread_interval(n.xi_z, s.xi_z, "xi_z"),
                  spread_interval(n.omega, s.omega, "omega"),
                  spread_interval(n.omega_z, s.omega_z, "omega_z")};
  validate(p);
  return p;
}

core::TransferFunction plant_transfer_function(const PlantParameters& p) {
  return {p.k * core::Polynomial{1.0, 2.0 * p.xi_z * p.omega_z, p.omega_z * p.omega_z},
          core::Polynomial{1.0, p.a} * core::Polynomial{1.0, 2.0 * p.xi * p.omega, p.omega * p.omega}};
}

core::Polynomial closed_loop_polynomial(const PlantParameters& p, const PiGains& gains) {
  const Quartic c = quartic_of(p, gains);
  return core::Polynomial(std::vector<double>(c.begin(), c.end()));
}

KharitonovResult kharitonov(const IntervalPlant& plant, const PiGains& gains) {
  validate(plant);
  check_gains(gains);
  // Monotone coefficients (header): the bounds are the all-lower and all-upper vertices.
  const Quartic lo = quartic_of(plant.lower(), gains), hi = quartic_of(plant.upper(), gains);
  KharitonovResult r;
  for (std::size_t k = 0; k < 4; ++k) {
    r.lower[k] = lo[4 - k];
    r.upper[k] = hi[4 - k];
  }
  const std::array<Quartic, 4> qs = kharitonov_quartics(lo, hi);
  r.robust = true;
  for (std::size_t i = 0; i < 4; ++i) {
    r.polynomials[i] = core::Polynomial(std::vector<double>(qs[i].begin(), qs[i].end()));
    r.hurwitz[i] = core::is_hurwitz(r.polynomials[i]);
    r.max_real_part[i] = max_real_part(r.polynomials[i]);
    r.robust = r.robust && r.hurwitz[i];
  }
  return r;
}

GridResult grid_check(const IntervalPlant& plant, const PiGains& gains, int points_per_parameter) {
  validate(plant);
  check_gains(gains);
  check_points(points_per_parameter);
  const int n = points_per_parameter;
  const std::vector<double> ks = grid_values(plant.k, n), as = grid_values(plant.a, n), xs = grid_values(plant.xi, n),
                            zs = grid_values(plant.xi_z, n), ws = grid_values(plant.omega, n),
                            wzs = grid_values(plant.omega_z, n);
  GridResult out;
  out.worst_max_real_part = -std::numeric_limits<double>::infinity();
  PlantParameters p;
  for (double k : ks)
    for (double a : as)
      for (double xi : xs)
        for (double xz : zs)
          for (double w : ws)
            for (double wz : wzs) {
              p = {k, a, xi, xz, w, wz};
              const Quartic c = quartic_of(p, gains);
              ++out.cases;
              if (!quartic_hurwitz(c)) {
                ++out.failures;
                if (!out.first_failure) out.first_failure = p;
              }
              // Worse than the current worst only if some root has Re >= α: c(s + α) not Hurwitz.
              if (out.cases > 1 && quartic_hurwitz(shifted(c, out.worst_max_real_part))) continue;
              const double alpha = max_real_part(core::Polynomial(std::vector<double>(c.begin(), c.end())));
              if (alpha > out.worst_max_real_part) {
                out.worst_max_real_part = alpha;
                out.worst = p;
              }
            }
  out.robust = out.failures == 0;
  return out;
}

bool robustly_stable(const IntervalPlant& plant, const PiGains& gains, int points_per_parameter) {
  validate(plant);
  check_gains(gains);
  check_points(points_per_parameter);
  // Same verdicts as kharitonov().robust || grid_check().robust, without their diagnostics.
  return kharitonov_robust(plant, gains) || grid_all_stable(plant, gains, points_per_parameter);
}

NormalizedPlant nominal_normalized_plant(const IntervalPlant& plant) {
  validate(plant);
  const PlantParameters n = plant.nominal();
  NormalizedPlant p = normalized_two_mass(n.omega / n.omega_z, n.xi_z, n.xi, n.a / n.omega_z);
  p.omega_z = n.omega_z;
  p.motor_inertia = 1.0 / n.k;  // P → K/s at high frequency
  return p;
}

PiGains nominal_pi_design(const IntervalPlant& plant, double omega_star, double zeta_star) {
  const NormalizedPlant p = nominal_normalized_plant(plant);
  detail::require_pair(omega_star, zeta_star);
  return to_physical(pi_pole_placement(p.motor(false), omega_star / p.omega_z, zeta_star).gains, p);
}

double largest_robust_omega_star(const IntervalPlant& plant, double zeta_star, int points_per_parameter) {
  const NormalizedPlant p = nominal_normalized_plant(plant);
  detail::require_positive(zeta_star, "zeta_star", "a damping ratio");
  check_points(points_per_parameter);
  const AdmissibleRange range = admissible_range(p, zeta_star);
  if (range.empty()) return 0.0;
  const core::TransferFunction model = p.motor(false);
  const auto passes = [&](double omega_n) {
    const PiGains g = to_physical(pi_pole_placement(model, omega_n, zeta_star).gains, p);
    // At a range end a gain may round to slightly below 0: not an admissible design.
    return g.kp >= 0.0 && g.ki >= 0.0 && robustly_stable(plant, g, points_per_parameter);
  };
  const double hi = range.omega_max;
  if (passes(hi)) return hi * p.omega_z;
  constexpr int kScan = 24;
  const double low = std::max(range.omega_min, 1e-3 * hi);
  double fail = hi;
  for (int j = kScan - 1; j >= 1; --j) {
    const double w = low * std::pow(hi / low, static_cast<double>(j) / kScan);
    if (!passes(w)) {
      fail = w;
      continue;
    }
    double pass = w;
    while (fail - pass > 1e-5 * hi) {
      const double mid = 0.5 * (pass + fail);
      (passes(mid) ? pass : fail) = mid;
    }
    return pass * p.omega_z;
  }
  return 0.0;
}

}  // namespace servotwin::tuning
