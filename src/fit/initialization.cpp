#include "servotwin/fit/initialization.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include "servotwin/core/polynomial.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// ln √2: the half-power level in nepers.
const double kHalfPower = 0.5 * std::log(2.0);
constexpr double kZetaMin = 1e-3;
constexpr double kZetaMax = 1.0;

struct Curve {
  std::vector<double> log_omega;
  std::vector<double> d;      ///< ln|ω V(jω)|
  std::vector<Complex> v;     ///< velocity-equivalent values
};

Curve detrended(const core::FrequencyResponse& response, OutputKind output) {
  Curve c;
  for (const auto& p : response.points) {
    const double w = kTwoPi * p.freq_hz;
    const Complex v = output == OutputKind::kPosition ? p.value * Complex(0.0, w) : p.value;
    c.log_omega.push_back(std::log(w));
    c.d.push_back(std::log(std::abs(v)) + std::log(w));
    c.v.push_back(v);
  }
  return c;
}

/// Prominence of the maximum of `y` at i: height above the higher of the lowest points reached on
/// each side before meeting a higher point (or the end).
double prominence(const std::vector<double>& y, std::size_t i) {
  double left = y[i], right = y[i];
  for (std::size_t k = i; k-- > 0;) {
    if (y[k] > y[i]) break;
    left = std::min(left, y[k]);
  }
  for (std::size_t k = i + 1; k < y.size(); ++k) {
    if (y[k] > y[i]) break;
    right = std::min(right, y[k]);
  }
  return y[i] - std::max(left, right);
}

/// Vertex of the parabola through three points, clamped to the outer two.
double parabola_vertex(double x0, double y0, double x1, double y1, double x2, double y2) {
  const double denom = (x0 - x1) * (x0 - x2) * (x1 - x2);
  const double a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / denom;
  const double b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / denom;
  if (!(std::abs(a) > 0.0) || !std::isfinite(a)) return x1;
  return std::clamp(-b / (2.0 * a), x0, x2);
}

/// Crossing of level `level` by y walking from i in direction `step`, interpolated linearly in
/// log ω; empty when y never crosses before the end or before turning back past the start value.
std::optional<double> crossing(const Curve& c, const std::vector<double>& y, std::size_t i, int step, double level) {
  std::size_t k = i;
  while (true) {
    if (step < 0 && k == 0) return std::nullopt;
    const std::size_t next = step < 0 ? k - 1 : k + 1;
    if (next >= y.size()) return std::nullopt;
    if (y[next] > y[i]) return std::nullopt;  // met a higher point first: not this extremum's band
    if (y[next] <= level) {
      const double t = (y[k] - level) / (y[k] - y[next]);
      return c.log_omega[k] + t * (c.log_omega[next] - c.log_omega[k]);
    }
    k = next;
  }
}

/// Extremum of y (maxima of y; minima are passed as −d) with its frequency and damping.
Extremum describe(const Curve& c, const std::vector<double>& y, std::size_t i) {
  Extremum e;
  e.index = i;
  e.prominence = prominence(y, i);
  const double log_w = parabola_vertex(c.log_omega[i - 1], y[i - 1], c.log_omega[i], y[i], c.log_omega[i + 1], y[i + 1]);
  e.omega_rad_s = std::exp(log_w);
  const double level = y[i] - kHalfPower;
  const auto lo = crossing(c, y, i, -1, level);
  const auto hi = crossing(c, y, i, +1, level);
  double zeta = 0.0;
  if (lo && hi) {
    zeta = (std::exp(*hi) - std::exp(*lo)) / (2.0 * e.omega_rad_s);
  } else if (lo || hi) {
    // One side resolved: the band is symmetric in ω to first order.
    const double edge = std::exp(lo ? *lo : *hi);
    zeta = std::abs(e.omega_rad_s - edge) / e.omega_rad_s;
  }
  if (zeta > 0.0) {
    e.zeta_method = "half-power";
  } else {
    // Phase falls (rises) by π across a resonance (antiresonance) with slope 1/(ζω) at its centre;
    // a secant over the neighbours underestimates the slope, so ζ errs high, which LM tolerates
    // better than a too-sharp start.
    const double dphi = std::abs(std::arg(c.v[i + 1] / c.v[i - 1]));
    const double dw = std::exp(c.log_omega[i + 1]) - std::exp(c.log_omega[i - 1]);
    zeta = dphi > 0.0 ? dw / (e.omega_rad_s * dphi) : kZetaMax;
    e.zeta_method = "phase-slope";
  }
  e.zeta = std::clamp(zeta, kZetaMin, kZetaMax);
  return e;
}

std::vector<Extremum> maxima(const Curve& c, const std::vector<double>& y) {
  std::vector<Extremum> out;
  // A pair with ζ ≥ 1/√2 has no peak of its own: a broader hump is the rigid pole meeting a lag
  // pole, not a mode.
  const double zeta_limit = 1.0 / std::sqrt(2.0);
  for (std::size_t i = 1; i + 1 < y.size(); ++i)
    if (y[i] > y[i - 1] && y[i] >= y[i + 1]) {
      Extremum e = describe(c, y, i);
      if (e.zeta < zeta_limit) out.push_back(e);
    }
  std::stable_sort(out.begin(), out.end(), [](const Extremum& a, const Extremum& b) { return a.prominence > b.prominence; });
  return out;
}

void require_finite_positive(double w) {
  if (!(std::isfinite(w) && w > 0.0)) throw std::invalid_argument("three_point_interpolation: frequencies must be finite and > 0");
}

}  // namespace

InterpolationResult three_point_interpolation(const std::array<double, 3>& omega_rad_s,
                                              const std::array<std::complex<double>, 3>& values, RigidKind rigid) {
  for (double w : omega_rad_s) require_finite_positive(w);
  for (const Complex& v : values)
    if (!(std::isfinite(v.real()) && std::isfinite(v.imag()) && std::abs(v) > 0.0))
      throw std::invalid_argument("three_point_interpolation: values must be finite and non-zero");
  if (omega_rad_s[0] == omega_rad_s[1] || omega_rad_s[1] == omega_rad_s[2] || omega_rad_s[0] == omega_rad_s[2])
    throw std::invalid_argument("three_point_interpolation: the three frequencies must differ");

  // Scale s by w_ref and P by g_ref so that every matrix entry is O(1); the unknowns become
  // alpha_k = a_k / w_ref^(3-k) and beta_k = b_k / (g_ref w_ref^(3-k)).
  const double w_ref = *std::max_element(omega_rad_s.begin(), omega_rad_s.end());
  const auto ref = static_cast<std::size_t>(std::max_element(omega_rad_s.begin(), omega_rad_s.end()) - omega_rad_s.begin());
  const double g_ref = std::abs(values[ref]);
  const bool integrator = rigid == RigidKind::kIntegrator;
  const Eigen::Index unknowns = integrator ? 5 : 6;
  Eigen::MatrixXd a(6, unknowns);
  Eigen::VectorXd rhs(6);
  for (std::size_t l = 0; l < 3; ++l) {
    const Complex s(0.0, omega_rad_s[l] / w_ref);
    const Complex p = values[l] / g_ref;
    // Unknown order: [alpha0 (absent for the integrator), alpha1, alpha2, beta0, beta1, beta2].
    std::vector<Complex> row;
    if (!integrator) row.push_back(-p);
    row.push_back(-p * s);
    row.push_back(-p * s * s);
    row.push_back(1.0);
    row.push_back(s);
    row.push_back(s * s);
    const Complex b = p * s * s * s;
    const auto re = static_cast<Eigen::Index>(2 * l), im = re + 1;
    for (Eigen::Index k = 0; k < unknowns; ++k) {
      a(re, k) = row[static_cast<std::size_t>(k)].real();
      a(im, k) = row[static_cast<std::size_t>(k)].imag();
    }
    rhs[re] = b.real();
    rhs[im] = b.imag();
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(rhs);
  const Eigen::Index o = integrator ? 0 : 1;
  const double a0 = integrator ? 0.0 : x[0] * w_ref * w_ref * w_ref;
  const double a1 = x[o] * w_ref * w_ref;
  const double a2 = x[o + 1] * w_ref;
  const double b0 = x[o + 2] * g_ref * w_ref * w_ref * w_ref;
  const double b1 = x[o + 3] * g_ref * w_ref * w_ref;
  const double b2 = x[o + 4] * g_ref * w_ref;

  InterpolationResult r;
  r.numerator = {b2, b1, b0};
  r.denominator = {1.0, a2, a1, a0};
  if (!x.allFinite()) {
    r.failure = "the three points do not determine the coefficients (singular system)";
    return r;
  }
  if (b2 == 0.0 || !(b0 / b2 > 0.0)) {
    r.failure = "the numerator has no complex zero pair (no antiresonance between the points)";
    return r;
  }
  const double wz = std::sqrt(b0 / b2);
  const double zz = b1 / (2.0 * b2 * wz);
  const auto roots = core::Polynomial{1.0, a2, a1, a0}.roots();
  std::optional<Complex> pair;
  std::optional<double> real_root;
  for (const Complex& z : roots) {
    if (z.imag() > 0.0) pair = z;
    if (z.imag() == 0.0 && (!real_root || std::abs(z.real()) < std::abs(*real_root))) real_root = z.real();
  }
  if (!pair) {
    r.failure = "the denominator has no complex pole pair (no resonance between the points)";
    return r;
  }
  const double wn = std::abs(*pair);
  const double zn = -pair->real() / wn;
  if (!(zz > 0.0) || !(zn > 0.0) || !real_root || (!integrator && !(*real_root < 0.0))) {
    r.failure = "the interpolated model is unstable or has non-minimum-phase zeros";
    return r;
  }
  PlantModel m;
  m.rigid = rigid;
  m.gain = b2;
  m.rigid_pole_rad_s = integrator ? 0.0 : -*real_root;
  m.modes.push_back(Mode{{wz, zz}, {wn, zn}});
  r.model = m;
  return r;
}

PeakPicking pick_peaks(const core::FrequencyResponse& response, OutputKind output) {
  PeakPicking result;
  if (response.size() < 3) return result;
  const Curve c = detrended(response, output);
  result.resonances = maxima(c, c.d);
  std::vector<double> neg(c.d.size());
  std::transform(c.d.begin(), c.d.end(), neg.begin(), [](double v) { return -v; });
  result.antiresonances = maxima(c, neg);
  return result;
}

ModePairing pair_modes(const PeakPicking& peaks, std::size_t modes) {
  if (peaks.resonances.size() < modes) {
    ModePairing out;
    out.failure = "found " + std::to_string(peaks.resonances.size()) + " resonance peak(s), the model needs " +
                  std::to_string(modes);
    return out;
  }
  return pair_modes(peaks, std::vector<Extremum>(peaks.resonances.begin(),
                                                 peaks.resonances.begin() + static_cast<std::ptrdiff_t>(modes)));
}

std::vector<std::vector<Extremum>> resonance_choices(const PeakPicking& peaks, std::size_t modes, std::size_t limit) {
  std::vector<std::vector<Extremum>> out;
  const std::size_t pool = std::min(peaks.resonances.size(), modes + 2);
  if (pool < modes || modes == 0) return out;
  // Lexicographic n-subsets of the pool indices: the first is the n most prominent.
  std::vector<std::size_t> pick(modes);
  std::iota(pick.begin(), pick.end(), std::size_t{0});
  while (out.size() < limit) {
    std::vector<Extremum> set;
    for (std::size_t i : pick) set.push_back(peaks.resonances[i]);
    out.push_back(std::move(set));
    std::size_t k = modes;
    while (k > 0 && pick[k - 1] == pool - modes + (k - 1)) --k;
    if (k == 0) break;
    ++pick[k - 1];
    for (std::size_t j = k; j < modes; ++j) pick[j] = pick[j - 1] + 1;
  }
  return out;
}

ModePairing pair_modes(const PeakPicking& peaks, std::vector<Extremum> chosen) {
  ModePairing out;
  std::sort(chosen.begin(), chosen.end(), [](const Extremum& a, const Extremum& b) { return a.index < b.index; });
  std::vector<bool> used(peaks.antiresonances.size(), false);
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const std::size_t lower = k == 0 ? 0 : chosen[k - 1].index;
    const std::size_t upper = k + 1 < chosen.size() ? chosen[k + 1].index : static_cast<std::size_t>(-1);
    // Most prominent unused minimum between the previous resonance and this one; else between this
    // one and the next (antiresonance above the resonance: non-collocated data).
    auto pick = [&](std::size_t from, std::size_t to) -> std::optional<std::size_t> {
      for (std::size_t j = 0; j < peaks.antiresonances.size(); ++j) {
        const std::size_t i = peaks.antiresonances[j].index;
        if (!used[j] && i >= from && i < to) return j;
      }
      return std::nullopt;
    };
    auto j = pick(lower, chosen[k].index);
    if (!j) j = pick(chosen[k].index + 1, upper);
    if (!j) {
      out.pairs.clear();
      out.failure = "no antiresonance (magnitude minimum) found next to the resonance at " +
                    std::to_string(chosen[k].omega_rad_s / kTwoPi) + " Hz";
      return out;
    }
    used[*j] = true;
    out.pairs.emplace_back(peaks.antiresonances[*j], chosen[k]);
  }
  return out;
}

std::optional<std::array<std::size_t, 3>> choose_interpolation_points(const core::FrequencyResponse& response,
                                                                      OutputKind output) {
  const PeakPicking peaks = pick_peaks(response, output);
  const ModePairing pairing = pair_modes(peaks, 1);
  if (pairing.pairs.empty()) return std::nullopt;
  const std::size_t anti = pairing.pairs.front().first.index;
  const std::size_t res = pairing.pairs.front().second.index;
  if (anti == 0 || res == 0) return std::nullopt;
  return std::array<std::size_t, 3>{0, std::min(anti, res), std::max(anti, res)};
}

}  // namespace servotwin::fit
