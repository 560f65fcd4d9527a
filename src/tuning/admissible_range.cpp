// Admissible bandwidth range of a PI (catalog C7.3, C7.6) and the C7.4 damping limit.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "checks.hpp"
#include "closed_forms.hpp"
#include "placement.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

namespace {

constexpr std::size_t kGridPoints = 96;
constexpr int kBisectionSteps = 60;
constexpr double kRadiusTolerance = 1e-9;
constexpr double kDivisionTolerance = 1e-6;
constexpr double kMinusInfinity = -std::numeric_limits<double>::infinity();

/// One candidate ω*: its verdict (kNone = admissible) and, when the gains are valid, the second pair.
struct Point {
  RangeLimit verdict = RangeLimit::kNone;
  std::optional<SecondPair> pair;
};

/// Evaluates candidates ω* for one plant, ζ* and ideal derivative gain.
class Scanner {
 public:
  Scanner(const NormalizedPlant& plant, double zeta_star, double kd)
      : problem_(plant.motor(false), kd, 0.0), zeta_(zeta_star) {}

  /// The admissible-range test; `with_radius` = false skips the dominance condition.
  [[nodiscard]] Point check(double omega, bool with_radius = true) const {
    const std::optional<PolePlacement> placed = detail::place(problem_, omega, zeta_);
    if (!placed) return {RangeLimit::kPlacement, std::nullopt};
    if (!(placed->gains.ki > 0.0)) return {RangeLimit::kIntegralGain, std::nullopt};
    if (!(placed->gains.kp > 0.0)) return {RangeLimit::kProportionalGain, std::nullopt};
    const core::Polynomial c = problem_.closed_loop(placed->gains);
    if (!core::is_hurwitz(c)) return {RangeLimit::kStability, std::nullopt};
    const std::optional<SecondPair> pair = detail::second_pair_of(c, omega, zeta_, kDivisionTolerance);
    if (!pair) return {RangeLimit::kPlacement, std::nullopt};
    if (with_radius && pair->min_radius < omega * (1.0 - kRadiusTolerance))
      return {RangeLimit::kSecondPairRadius, pair};
    return {RangeLimit::kNone, pair};
  }

 private:
  detail::PlacementProblem problem_;
  double zeta_;
};

/// The scan's upper end: 1 (= ωz), or the positive-gain root of eq. 7.63 for an exactly
/// frictionless plant (on the virtual plant of the ideal derivative kd, catalog C7.5).
detail::GainRoot upper_end(const NormalizedPlant& plant, double zeta_star, double kd) {
  const bool frictionless = plant.a == 0.0 && std::abs(plant.zeta_p - plant.r * plant.zeta_z) <=
                                                  1e-12 * std::max(plant.zeta_p, 1e-300);
  if (!frictionless) return {1.0, RangeLimit::kFullBandwidth};
  const double r_virtual = std::sqrt((plant.r * plant.r + kd) / (1.0 + kd));
  return detail::frictionless_gain_root(r_virtual, plant.zeta_z, zeta_star);
}

std::vector<double> scan_grid(const NormalizedPlant& plant, double upper) {
  double lower = 1e-3 * upper;
  if (plant.a > 0.0) lower = std::min(lower, plant.a / 100.0);
  return core::log_space(lower, upper, kGridPoints);
}

/// Verdicts on the grid; the last point is the upper end itself, which fails with the gain-root
/// reason when the end is a root of eq. 7.63 (the gain vanishes there).
std::vector<RangeLimit> verdicts(const Scanner& scanner, const std::vector<double>& grid, const detail::GainRoot& end) {
  std::vector<RangeLimit> v(grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const bool at_root = i + 1 == grid.size() && end.limit != RangeLimit::kFullBandwidth;
    v[i] = at_root ? end.limit : scanner.check(grid[i]).verdict;
  }
  return v;
}

/// Bisection (geometric) between a passing and a failing ω*; returns the passing end and sets
/// `reason` to the failure at the other end.
double bisect(const Scanner& scanner, double pass, double fail, RangeLimit& reason) {
  for (int i = 0; i < kBisectionSteps; ++i) {
    const double mid = std::sqrt(pass * fail);
    if (mid == pass || mid == fail) break;
    const RangeLimit v = scanner.check(mid).verdict;
    if (v == RangeLimit::kNone) {
      pass = mid;
    } else {
      fail = mid;
      reason = v;
    }
  }
  return pass;
}

void check_kd(double kd) {
  detail::require_finite(kd, "kd");
  if (kd <= -1.0)
    throw core::InputError(core::at_field("kd"), "expected Kd > -1 (the virtual motor inertia 1 + Kd must stay > 0), got " +
                                                     detail::show(kd));
}

/// Golden-section maximum of ζ2 on [lo, hi] (a unimodal neighbourhood of the best grid point).
DampingLimit golden_max(const Scanner& scanner, double lo, double hi) {
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  const auto zeta2 = [&](double w) {
    const Point p = scanner.check(w, false);
    return p.pair ? p.pair->zeta : kMinusInfinity;
  };
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = zeta2(x1), f2 = zeta2(x2);
  while (hi - lo > 1e-10 * hi) {
    if (f1 >= f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - g * (hi - lo);
      f1 = zeta2(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + g * (hi - lo);
      f2 = zeta2(x2);
    }
  }
  return f1 >= f2 ? DampingLimit{f1, x1} : DampingLimit{f2, x2};
}

}  // namespace

std::string to_string(RangeLimit limit) {
  switch (limit) {
    case RangeLimit::kNone: return "none";
    case RangeLimit::kFullBandwidth: return "full bandwidth";
    case RangeLimit::kIntegralGain: return "Ki <= 0";
    case RangeLimit::kProportionalGain: return "Kp <= 0";
    case RangeLimit::kStability: return "closed loop unstable";
    case RangeLimit::kSecondPairRadius: return "second pair radius";
    case RangeLimit::kPlacement: return "pair cannot be placed";
  }
  return "unknown";
}

AdmissibleRange admissible_range(const NormalizedPlant& plant, double zeta_star, double kd) {
  detail::require_positive(zeta_star, "zeta_star", "a damping ratio");
  check_kd(kd);
  const detail::GainRoot end = upper_end(plant, zeta_star, kd);
  const Scanner scanner(plant, zeta_star, kd);
  const std::vector<double> grid = scan_grid(plant, end.omega);
  const std::vector<RangeLimit> v = verdicts(scanner, grid, end);

  std::size_t first = 0;
  while (first < v.size() && v[first] != RangeLimit::kNone) ++first;
  AdmissibleRange range;
  if (first == v.size()) {
    range.upper = v.front();
    return range;
  }
  if (first > 0) {
    range.lower = v[first - 1];
    range.omega_min = bisect(scanner, grid[first], grid[first - 1], range.lower);
  }
  std::size_t last = first;
  while (last + 1 < v.size() && v[last + 1] == RangeLimit::kNone) ++last;
  if (last + 1 == v.size()) {
    range.omega_max = grid.back();
    range.upper = RangeLimit::kFullBandwidth;
    return range;
  }
  range.upper = v[last + 1];
  range.omega_max = bisect(scanner, grid[last], grid[last + 1], range.upper);
  return range;
}

DampingLimit max_second_pair_damping(const NormalizedPlant& plant, double zeta_star) {
  detail::require_positive(zeta_star, "zeta_star", "a damping ratio");
  const detail::GainRoot end = upper_end(plant, zeta_star, 0.0);
  const Scanner scanner(plant, zeta_star, 0.0);
  const std::vector<double> grid = scan_grid(plant, end.omega);
  std::vector<double> zeta2(grid.size(), kMinusInfinity);
  std::size_t best = grid.size();
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (i + 1 == grid.size() && end.limit != RangeLimit::kFullBandwidth) break;  // a gain vanishes there
    const Point p = scanner.check(grid[i], false);
    if (p.verdict != RangeLimit::kNone) continue;
    zeta2[i] = p.pair->zeta;
    if (best == grid.size() || zeta2[i] > zeta2[best]) best = i;
  }
  if (best == grid.size())
    throw core::InputError(core::at_field("zeta_star"),
                           "no bandwidth in (0, 1] gives positive PI gains and a stable loop for zeta_star = " +
                               detail::show(zeta_star));
  const double lo = best > 0 && std::isfinite(zeta2[best - 1]) ? grid[best - 1] : grid[best];
  const double hi = best + 1 < grid.size() && std::isfinite(zeta2[best + 1]) ? grid[best + 1] : grid[best];
  const DampingLimit refined = lo < hi ? golden_max(scanner, lo, hi) : DampingLimit{zeta2[best], grid[best]};
  return refined.zeta2_max >= zeta2[best] ? refined : DampingLimit{zeta2[best], grid[best]};
}

}  // namespace servotwin::tuning
