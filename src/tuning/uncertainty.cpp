#include "servotwin/tuning/uncertainty.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "checks.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/norms.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {

namespace {

using core::InputError;
using core::Polynomial;
using core::TransferFunction;
using detail::show;

constexpr double kInf = std::numeric_limits<double>::infinity();

// ------------------------------------------------------------------------- envelope fit

/// A binding point of the envelope in log coordinates.
struct LogPoint {
  double omega2 = 0.0;  ///< ω²
  double log_bound = 0.0;
  double weight = 0.0;  ///< trapezoid weight in log ω, summing to 1
};

/// Corners of the shape g = Π (s + z_i)/(s + p_i); `integrating` pins z_0 = 0.
struct Shape {
  std::vector<double> log_corners;  ///< [log z_i (skipping z_0 when integrating)..., log p_i...]
  bool integrating = false;
  int order = 1;

  [[nodiscard]] double zero(const std::vector<double>& x, int i) const {
    if (integrating) return i == 0 ? 0.0 : std::exp(x[static_cast<std::size_t>(i - 1)]);
    return std::exp(x[static_cast<std::size_t>(i)]);
  }
  [[nodiscard]] double pole(const std::vector<double>& x, int i) const {
    const int zeros = integrating ? order - 1 : order;
    return std::exp(x[static_cast<std::size_t>(zeros + i)]);
  }
  /// log|g(jω)|.
  [[nodiscard]] double log_gain(const std::vector<double>& x, double omega2) const {
    double v = 0.0;
    for (int i = 0; i < order; ++i) {
      const double z = zero(x, i), p = pole(x, i);
      v += 0.5 * (std::log(omega2 + z * z) - std::log(omega2 + p * p));
    }
    return v;
  }
};

/// log k of the tightest envelope of this shape, and its log-area.
std::pair<double, double> envelope_of(const Shape& shape, const std::vector<double>& x,
                                      const std::vector<LogPoint>& pts) {
  double log_k = -kInf;
  std::vector<double> g(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    g[i] = shape.log_gain(x, pts[i].omega2);
    log_k = std::max(log_k, pts[i].log_bound - g[i]);
  }
  double area = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) area += pts[i].weight * (log_k + g[i] - pts[i].log_bound);
  return {log_k, area};
}

/// Nelder–Mead on a non-smooth but continuous function (the envelope's area is a max of smooth
/// functions); restarted from the best vertex until a restart no longer improves.
std::vector<double> nelder_mead(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x0,
                                double step) {
  const std::size_t n = x0.size();
  double best_value = f(x0);
  for (int restart = 0; restart < 6; ++restart) {
    std::vector<std::vector<double>> simplex(n + 1, x0);
    std::vector<double> values(n + 1);
    for (std::size_t i = 0; i < n; ++i) simplex[i + 1][i] += step;
    for (std::size_t i = 0; i <= n; ++i) values[i] = f(simplex[i]);
    for (int it = 0; it < 4000; ++it) {
      std::vector<std::size_t> order(n + 1);
      for (std::size_t i = 0; i <= n; ++i) order[i] = i;
      std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
      const std::size_t best = order.front(), worst = order.back(), second = order[n - 1];
      double size = 0.0;
      for (std::size_t i = 0; i <= n; ++i)
        for (std::size_t j = 0; j < n; ++j) size = std::max(size, std::abs(simplex[i][j] - simplex[best][j]));
      if (size < 1e-11) break;
      std::vector<double> centroid(n, 0.0);
      for (std::size_t i = 0; i <= n; ++i)
        if (i != worst)
          for (std::size_t j = 0; j < n; ++j) centroid[j] += simplex[i][j] / static_cast<double>(n);
      const auto along = [&](double t) {
        std::vector<double> y(n);
        for (std::size_t j = 0; j < n; ++j) y[j] = centroid[j] + t * (simplex[worst][j] - centroid[j]);
        return y;
      };
      std::vector<double> xr = along(-1.0);
      const double fr = f(xr);
      if (fr < values[best]) {
        std::vector<double> xe = along(-2.0);
        const double fe = f(xe);
        if (fe < fr) {
          simplex[worst] = xe;
          values[worst] = fe;
        } else {
          simplex[worst] = xr;
          values[worst] = fr;
        }
      } else if (fr < values[second]) {
        simplex[worst] = xr;
        values[worst] = fr;
      } else {
        std::vector<double> xc = along(fr < values[worst] ? -0.5 : 0.5);
        const double fc = f(xc);
        if (fc < std::min(fr, values[worst])) {
          simplex[worst] = xc;
          values[worst] = fc;
        } else {
          for (std::size_t i = 0; i <= n; ++i) {
            if (i == best) continue;
            for (std::size_t j = 0; j < n; ++j) simplex[i][j] = simplex[best][j] + 0.5 * (simplex[i][j] - simplex[best][j]);
            values[i] = f(simplex[i]);
          }
        }
      }
    }
    const auto it = std::min_element(values.begin(), values.end());
    const std::vector<double> x = simplex[static_cast<std::size_t>(it - values.begin())];
    const bool improved = *it < best_value - 1e-15 * std::max(1.0, std::abs(best_value));
    if (*it <= best_value) {
      best_value = *it;
      x0 = x;
    }
    if (!improved) break;
    step *= 0.5;
  }
  return x0;
}

struct Candidate {
  Shape shape;
  std::vector<double> x;
  double area = kInf;
};

Candidate refine(const Shape& shape, std::vector<double> x0, const std::vector<LogPoint>& pts, double step) {
  const auto area = [&](const std::vector<double>& x) { return envelope_of(shape, x, pts).second; };
  Candidate c{shape, nelder_mead(area, std::move(x0), step), 0.0};
  c.area = area(c.x);
  return c;
}

/// Best first-order shape: coarse grid over the corners, then Nelder–Mead; both with z = 0 and z > 0.
Candidate fit_first_order(const std::vector<LogPoint>& pts, double log_lo, double log_hi) {
  constexpr int kGrid = 41;
  const double a = log_lo - std::log(100.0), b = log_hi + std::log(100.0);
  const auto at = [&](int i) { return a + (b - a) * i / (kGrid - 1); };
  Candidate best;
  const Shape integrating{{}, true, 1};
  const Shape general{{}, false, 1};
  for (int j = 0; j < kGrid; ++j) {
    const std::vector<double> x{at(j)};
    const double area = envelope_of(integrating, x, pts).second;
    if (area < best.area) best = {integrating, x, area};
    for (int i = 0; i < kGrid; ++i) {
      const std::vector<double> y{at(i), at(j)};
      const double area2 = envelope_of(general, y, pts).second;
      if (area2 < best.area) best = {general, y, area2};
    }
  }
  // Refine the best of each kind: the integrating one may be the answer even when a general
  // grid point is marginally better.
  Candidate out = refine(best.shape, best.x, pts, (b - a) / (kGrid - 1));
  if (!best.shape.integrating) {
    Candidate bi;
    for (int j = 0; j < kGrid; ++j) {
      const std::vector<double> x{at(j)};
      const double area = envelope_of(integrating, x, pts).second;
      if (area < bi.area) bi = {integrating, x, area};
    }
    Candidate ri = refine(bi.shape, bi.x, pts, (b - a) / (kGrid - 1));
    if (ri.area <= out.area) out = ri;
  }
  return out;
}

Candidate fit_second_order(const Candidate& first, const std::vector<LogPoint>& pts, double log_lo, double log_hi) {
  Shape shape{{}, first.shape.integrating, 2};
  const double mid = 0.5 * (log_lo + log_hi);
  std::vector<double> x;
  if (first.shape.integrating) {
    x = {mid, first.x[0], mid};  // z2, p1, p2
  } else {
    x = {first.x[0], mid, first.x[1], mid};  // z1, z2, p1, p2
  }
  x[x.size() - 1] += 0.1;  // a nearly neutral second section (z2 ≈ p2) starts at the order-1 area
  Candidate c = refine(shape, x, pts, 0.5);
  return c.area < first.area ? c : first;
}

TransferFunction to_transfer_function(const Candidate& c, double log_k) {
  Polynomial num{std::exp(log_k)}, den{1.0};
  for (int i = 0; i < c.shape.order; ++i) {
    num = num * Polynomial{1.0, c.shape.zero(c.x, i)};
    den = den * Polynomial{1.0, c.shape.pole(c.x, i)};
  }
  return {num, den};
}

// ------------------------------------------------------------------------- robustness tests

void check_weight(const TransferFunction& w2) {
  if (!w2.is_proper())
    throw InputError(core::at_field("w2"), "expected a proper weight W2 (degree of numerator <= denominator)");
  if (w2.den().degree() > 0 && !core::is_hurwitz(w2.den()))
    throw InputError(core::at_field("w2"), "expected a stable weight W2 (all poles in the open left half-plane)");
}

void check_options(const RobustnessOptions& o) {
  detail::require_grid(o.omega_min, o.omega_max, o.grid_points, o.rel_tol, "options.");
}

std::vector<double> robustness_grid(const VelocityLoop& loop, const TransferFunction& w2, const RobustnessOptions& o) {
  std::vector<double> grid = core::log_space(o.omega_min, o.omega_max, o.grid_points);
  const auto add = [&](double w) {
    if (w > o.omega_min && w < o.omega_max) grid.push_back(w);
  };
  for (const std::complex<double>& p : loop.characteristic_polynomial().roots()) {
    const double m = std::abs(p);
    if (m > 0.0 && -p.real() / m < 0.5) add(std::abs(p.imag()));
  }
  for (const std::complex<double>& p : w2.poles()) add(std::abs(p));
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

RobustnessResult evaluate(const VelocityLoop& loop, const TransferFunction& w2, double ms, const RobustnessOptions& o) {
  const std::vector<double> grid = robustness_grid(loop, w2, o);
  RobustnessResult r;
  const auto wt = [&](double w) { return w2.frequency_response(w) * loop.complementary(w); };
  const auto ws = [&](double w) { return loop.sensitivity(w) / ms; };
  const auto sum = [&](double w) { return std::complex<double>(std::abs(ws(w)) + std::abs(wt(w)), 0.0); };
  const core::PeakResult rs = core::peak_on_grid(wt, grid, o.rel_tol);
  const core::PeakResult np = core::peak_on_grid(ws, grid, o.rel_tol);
  const core::PeakResult rp = core::peak_on_grid(sum, grid, o.rel_tol);
  r.rs = rs.value;
  r.rs_omega = rs.omega_rad_s;
  r.np = np.value;
  r.np_omega = np.omega_rad_s;
  r.rp = rp.value;
  r.rp_omega = rp.omega_rad_s;
  r.nominally_stable = loop.stable();
  r.rs_ok = r.nominally_stable && r.rs < 1.0;
  r.np_ok = r.nominally_stable && r.np < 1.0;
  r.rp_ok = r.nominally_stable && r.rp < 1.0;
  return r;
}

}  // namespace

// ------------------------------------------------------------------------- residuals and W2

std::vector<ResidualBound> relative_residuals(const fit::PlantModel& nominal, const core::FrequencyResponse& measured) {
  if (measured.points.empty()) throw InputError(core::at_field("measured.points"), "expected at least one point");
  std::vector<ResidualBound> out;
  out.reserve(measured.points.size());
  double previous = 0.0;
  for (std::size_t i = 0; i < measured.points.size(); ++i) {
    const core::FrequencyPoint& p = measured.points[i];
    const std::string at = "measured.points[" + std::to_string(i) + "].";
    detail::require_positive(p.freq_hz, at + "freq_hz", "a frequency");
    if (i > 0 && !(p.freq_hz > previous))
      throw InputError(core::at_field(at + "freq_hz"),
                       "expected strictly increasing frequencies, got " + show(p.freq_hz) + " after " + show(previous));
    previous = p.freq_hz;
    if (!std::isfinite(p.value.real()) || !std::isfinite(p.value.imag()))
      throw InputError(core::at_field(at + "value"), "expected a finite response value");
    detail::require_non_negative(p.std_dev, at + "std_dev", "a standard deviation");
    const double omega = 2.0 * std::numbers::pi * p.freq_hz;
    const std::complex<double> pn = nominal.response(omega);
    const double mag = std::abs(pn);
    if (!std::isfinite(mag) || mag == 0.0)
      throw InputError(core::at_field(at + "freq_hz"),
                       "the nominal model is zero or not finite at " + show(p.freq_hz) + " Hz: no relative error defined");
    double bound = std::abs(p.value / pn - 1.0);
    if (p.std_dev > 0.0) bound += 2.0 * p.std_dev / mag;
    out.push_back({omega, bound});
  }
  return out;
}

UncertaintyEnvelope fit_uncertainty_envelope(std::span<const ResidualBound> residuals, int order) {
  if (order != 1 && order != 2)
    throw InputError(core::at_field("order"), "expected a weight order of 1 or 2, got " + std::to_string(order));
  std::vector<ResidualBound> pts;
  for (std::size_t i = 0; i < residuals.size(); ++i) {
    const std::string at = "residuals[" + std::to_string(i) + "].";
    detail::require_positive(residuals[i].omega, at + "omega", "a frequency");
    detail::require_non_negative(residuals[i].bound, at + "bound", "an error bound");
    if (residuals[i].bound > 0.0) pts.push_back(residuals[i]);
  }
  if (pts.size() < 3)
    throw InputError(core::at_field("residuals"),
                     "expected at least 3 points with a positive error bound, got " + std::to_string(pts.size()));
  std::sort(pts.begin(), pts.end(), [](const ResidualBound& a, const ResidualBound& b) { return a.omega < b.omega; });
  // Scale frequencies to the geometric middle of the data so that corners are O(1) in the search.
  const double log_lo = std::log(pts.front().omega), log_hi = std::log(pts.back().omega);
  const double scale = std::exp(0.5 * (log_lo + log_hi));
  const double span = log_hi - log_lo;
  std::vector<LogPoint> lp(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double w = pts[i].omega / scale;
    lp[i].omega2 = w * w;
    lp[i].log_bound = std::log(pts[i].bound);
    if (span > 0.0) {
      const double left = i == 0 ? 0.0 : std::log(pts[i].omega / pts[i - 1].omega);
      const double right = i + 1 == pts.size() ? 0.0 : std::log(pts[i + 1].omega / pts[i].omega);
      lp[i].weight = 0.5 * (left + right) / span;
    } else {
      lp[i].weight = 1.0 / static_cast<double>(pts.size());
    }
  }
  const double half = 0.5 * span;
  Candidate best = fit_first_order(lp, -half, half);
  if (order == 2) best = fit_second_order(best, lp, -half, half);
  const double log_k = envelope_of(best.shape, best.x, lp).first;

  // Undo the frequency scaling: (s/c + z)/(s/c + p) = (s + c z)/(s + c p) — only the corners move.
  Candidate physical = best;
  for (double& v : physical.x) v += std::log(scale);
  UncertaintyEnvelope out{to_transfer_function(physical, log_k), best.area, kInf};
  for (const ResidualBound& p : pts)
    out.min_ratio = std::min(out.min_ratio, std::abs(out.w2.frequency_response(p.omega)) / p.bound);
  return out;
}

UncertaintyEnvelope uncertainty_weight_from_residuals(const fit::PlantModel& nominal, const core::FrequencyResponse& measured,
                                                      int order) {
  const std::vector<ResidualBound> r = relative_residuals(nominal, measured);
  return fit_uncertainty_envelope(r, order);
}

TransferFunction to_normalized_time(const TransferFunction& w2, double omega_z) {
  detail::require_positive(omega_z, "omega_z", "a time scale");
  const auto scale = [&](const Polynomial& p) {
    std::vector<double> c(p.coefficients().begin(), p.coefficients().end());
    const int n = p.degree();
    for (int i = 0; i <= n; ++i) c[static_cast<std::size_t>(i)] *= std::pow(omega_z, n - i);
    return Polynomial(c);
  };
  return TransferFunction(scale(w2.num()), scale(w2.den())).normalized();
}

// ------------------------------------------------------------------------- RS / NP / RP

RobustnessResult robustness(const VelocityLoop& loop, const TransferFunction& w2, double ms,
                            const RobustnessOptions& options) {
  if (!std::isfinite(ms) || ms <= 1.0)
    throw InputError(core::at_field("ms"), "expected a sensitivity limit M_S > 1, got " + show(ms));
  check_weight(w2);
  check_options(options);
  return evaluate(loop, w2, ms, options);
}

RobustTracking robust_tracking(const VelocityLoop& loop, const TransferFunction& w2, double mt,
                               const RobustnessOptions& options) {
  if (!std::isfinite(mt) || mt < 1.0)
    throw InputError(core::at_field("mt"), "expected a tracking peak limit M_T >= 1, got " + show(mt));
  check_weight(w2);
  check_options(options);
  RobustTracking out;
  out.value = std::numeric_limits<double>::infinity();
  if (!loop.stable()) return out;
  const std::vector<double> grid = robustness_grid(loop, w2, options);
  const auto wt = [&](double w) { return w2.frequency_response(w) * loop.complementary(w); };
  const core::PeakResult rs = core::peak_on_grid(wt, grid, options.rel_tol);
  if (!(rs.value < 1.0)) {
    out.omega = rs.omega_rad_s;
    return out;
  }
  // Finite on the whole grid: |W2 T| < 1 everywhere (its refined supremum is).
  const auto bound = [&](double w) {
    const std::complex<double> tracking = loop.measures_load() ? loop.load_tracking(w) : loop.motor_tracking(w);
    const double gain = std::abs(tracking) * (1.0 + std::abs(w2.frequency_response(w))) /
                        (1.0 - std::abs(wt(w)));
    return std::complex<double>(gain / mt, 0.0);
  };
  const core::PeakResult peak = core::peak_on_grid(bound, grid, options.rel_tol);
  out.value = peak.value;
  out.omega = peak.omega_rad_s;
  return out;
}

std::string to_string(UncertaintyLimit limit) {
  switch (limit) {
    case UncertaintyLimit::kAdmissibleRange: return "admissible range";
    case UncertaintyLimit::kRobustStability: return "robust stability";
    case UncertaintyLimit::kNominalPerformance: return "nominal performance";
    case UncertaintyLimit::kRobustPerformance: return "robust performance";
    case UncertaintyLimit::kNothingPasses: return "nothing passes";
  }
  return "unknown";
}

UncertaintyOmegaStar largest_omega_star_with_uncertainty(const NormalizedPlant& plant, double zeta_star,
                                                         const TransferFunction& w2, double ms,
                                                         const UncertaintySearch& search) {
  detail::require_positive(zeta_star, "zeta_star", "a damping ratio");
  if (!std::isfinite(ms) || ms <= 1.0)
    throw InputError(core::at_field("ms"), "expected a sensitivity limit M_S > 1, got " + show(ms));
  check_weight(w2);
  check_options(search.grid);
  if (search.scan_points < 2 || search.scan_points > 1000)
    throw InputError(core::at_field("scan_points"), "expected 2 .. 1000 scan points");
  detail::require_non_negative(search.tau, "tau", "a derivative filter time constant");
  detail::require_finite(search.kd, "kd");

  UncertaintyOmegaStar out;
  const AdmissibleRange range = admissible_range(plant, zeta_star, search.kd);
  if (range.empty()) return out;
  const TransferFunction design_model = plant.motor(false);

  struct Evaluation {
    bool pass = false;
    UncertaintyLimit failure = UncertaintyLimit::kNothingPasses;
    PiGains gains;
    RobustnessResult result;
  };
  const auto evaluate_at = [&](double omega_star) {
    Evaluation e;
    try {
      e.gains = pi_pole_placement(design_model, omega_star, zeta_star, search.kd, search.tau).gains;
    } catch (const InputError&) {
      return e;  // the pair cannot be placed here
    }
    if (!(e.gains.kp > 0.0 && e.gains.ki > 0.0)) return e;
    const VelocityLoop loop(plant, PidGains{e.gains.kp, e.gains.ki, search.kd, search.tau, 1.0, 0.0}, search.with_hf);
    e.result = evaluate(loop, w2, ms, search.grid);
    if (!e.result.rs_ok) {
      e.failure = UncertaintyLimit::kRobustStability;
    } else if (search.test == RobustTest::kRobustPerformance && !e.result.np_ok) {
      e.failure = UncertaintyLimit::kNominalPerformance;
    } else if (search.test == RobustTest::kRobustPerformance && !e.result.rp_ok) {
      e.failure = UncertaintyLimit::kRobustPerformance;
    } else {
      e.pass = true;
    }
    return e;
  };
  const auto accept = [&](double omega_star, const Evaluation& e, UncertaintyLimit limit) {
    out.omega_star = omega_star;
    out.gains = e.gains;
    out.at_omega_star = e.result;
    out.limit = limit;
  };

  const double hi = range.omega_max;
  Evaluation top = evaluate_at(hi);
  if (top.pass) {
    accept(hi, top, UncertaintyLimit::kAdmissibleRange);
    return out;
  }
  const double lo = std::max(range.omega_min, 1e-3 * hi);
  const std::size_t n = search.scan_points;
  double fail_at = hi;
  Evaluation fail_eval = top;
  for (std::size_t j = n - 1; j-- > 0;) {
    const double w = lo * std::pow(hi / lo, static_cast<double>(j) / static_cast<double>(n - 1));
    Evaluation e = evaluate_at(w);
    if (!e.pass) {
      fail_at = w;
      fail_eval = std::move(e);
      continue;
    }
    double pass_at = w;
    Evaluation pass_eval = std::move(e);
    while (fail_at - pass_at > 1e-6 * hi) {
      const double mid = 0.5 * (pass_at + fail_at);
      Evaluation m = evaluate_at(mid);
      if (m.pass) {
        pass_at = mid;
        pass_eval = std::move(m);
      } else {
        fail_at = mid;
        fail_eval = std::move(m);
      }
    }
    accept(pass_at, pass_eval, fail_eval.failure);
    return out;
  }
  return out;
}

}  // namespace servotwin::tuning
