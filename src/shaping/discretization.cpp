// Discrete-time shapers: exact vector decomposition, rounding and p1 grid adjustment (C6.5).
#include "servotwin/shaping/discretization.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "discrete_text.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::shaping {

namespace {

using discrete_detail::num;

using core::at_field;
using core::InputError;

// Beyond this a "real-time" ring buffer would be absurd (10^7 samples = 2.8 h at 1 ms).
constexpr double kMaxDelaySamples = 1e7;
// A time within this many samples of a grid point is on it (times computed as 3 * T etc.).
constexpr double kOnGridTolerance = 1e-9;

void require_finite_positive(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0.0)
    throw InputError(at_field(field), "expected a finite value > 0, got " + num(value));
}

void require_mode(double omega, double zeta) {
  require_finite_positive(omega, "omega");
  if (!std::isfinite(zeta) || zeta < 0.0 || zeta >= 1.0)
    throw InputError(at_field("zeta"), "expected a damping in [0, 1), got " + num(zeta));
}

void validate_shaper(const Shaper& shaper) {
  if (shaper.times.empty()) throw InputError(at_field("times"), "the shaper has no pulses");
  if (shaper.amplitudes.size() != shaper.times.size())
    throw InputError(at_field("amplitudes"), "expected " + num(shaper.times.size()) +
                                                 " amplitudes (one per time), got " + num(shaper.amplitudes.size()));
  if (shaper.times.front() != 0.0)
    throw InputError(at_field("times[0]"), "the first pulse must be at t = 0, got " + num(shaper.times.front()));
  for (std::size_t i = 0; i < shaper.times.size(); ++i) {
    if (!std::isfinite(shaper.times[i]) || (i > 0 && !(shaper.times[i] > shaper.times[i - 1])))
      throw InputError(at_field("times[" + num(i) + "]"),
                       "expected finite, strictly increasing times, got " + num(shaper.times[i]));
    if (!std::isfinite(shaper.amplitudes[i]))
      throw InputError(at_field("amplitudes[" + num(i) + "]"), "expected a finite amplitude");
  }
}

double damped_frequency(double omega, double zeta) { return omega * std::sqrt(1.0 - zeta * zeta); }

// ω_d ts < π: below it the two-sample decomposition is well posed (C6.5 caveat).
void require_resolvable(double omega, double zeta, double ts) {
  const double wd = damped_frequency(omega, zeta);
  const double half_period = std::numbers::pi / wd;
  if (ts >= half_period)
    throw InputError(at_field("ts"), "sample period " + num(ts) + " s is not below half the damped period " +
                                         num(half_period) + " s of the mode (omega = " + num(omega) +
                                         " rad/s, zeta = " + num(zeta) + "): the grid cannot represent it");
}

// Grid index of a time and whether it is on the grid.
struct GridPosition {
  double k = 0.0;  // floor (or the nearest index when on the grid)
  bool on_grid = false;
};

GridPosition locate(double t, double ts) {
  const double x = t / ts;
  const double nearest = std::round(x);
  if (std::abs(x - nearest) <= kOnGridTolerance * std::max(1.0, nearest)) return {nearest, true};
  return {std::floor(x), false};
}

using PulseMap = std::map<std::size_t, double>;

void split_exact(double t, double amplitude, double k, double ts, double omega, double zeta, PulseMap& pulses) {
  const double sigma = zeta * omega, wd = damped_frequency(omega, zeta);
  const double t_minus = k * ts, t_plus = (k + 1.0) * ts;
  // a_i = A_i e^{σ t_i}; A± = a± e^{-σ t±}: combine the exponentials to avoid overflow on long
  // shapers with strong damping.
  const double det = std::sin(wd * ts);
  const double a_minus = amplitude * std::exp(sigma * (t - t_minus)) * std::sin(wd * (t_plus - t)) / det;
  const double a_plus = amplitude * std::exp(sigma * (t - t_plus)) * std::sin(wd * (t - t_minus)) / det;
  const auto index = static_cast<std::size_t>(k);
  pulses[index] += a_minus;
  pulses[index + 1] += a_plus;
}

}  // namespace

const char* discretization_method_name(DiscretizationMethod method) noexcept {
  return method == DiscretizationMethod::Exact ? "exact" : "round";
}

Shaper DiscreteShaper::to_shaper() const {
  Shaper s;
  s.type = type;
  s.omega = omega;
  s.zeta = zeta;
  s.amplitudes = amplitudes;
  s.times.reserve(delays.size());
  for (const std::size_t d : delays) s.times.push_back(static_cast<double>(d) * ts);
  return s;
}

DiscreteShaper discretize(const Shaper& shaper, double ts, DiscretizationMethod method) {
  require_finite_positive(ts, "ts");
  validate_shaper(shaper);
  require_mode(shaper.omega, shaper.zeta);
  require_resolvable(shaper.omega, shaper.zeta, ts);
  if (shaper.duration() / ts > kMaxDelaySamples)
    throw InputError(at_field("ts"), "the shaper lasts " + num(shaper.duration()) +
                                         " s = " + num(shaper.duration() / ts) + " samples of " + num(ts) +
                                         " s; at most " + num(kMaxDelaySamples) + " samples are supported");

  PulseMap pulses;
  for (std::size_t i = 0; i < shaper.times.size(); ++i) {
    const double t = shaper.times[i], a = shaper.amplitudes[i];
    const GridPosition where = locate(t, ts);
    if (where.on_grid) {
      pulses[static_cast<std::size_t>(where.k)] += a;
    } else if (method == DiscretizationMethod::Round) {
      pulses[static_cast<std::size_t>(std::floor(t / ts + 0.5))] += a;
    } else {
      split_exact(t, a, where.k, ts, shaper.omega, shaper.zeta, pulses);
    }
  }

  double sum = 0.0;
  for (const auto& [k, a] : pulses) sum += a;
  if (!(sum > 0.0))
    throw InputError(at_field("amplitudes"), "the discretized amplitudes sum to " + num(sum) +
                                                 " (expected > 0): the shaper has no static gain");

  DiscreteShaper out;
  out.type = shaper.type;
  out.omega = shaper.omega;
  out.zeta = shaper.zeta;
  out.ts = ts;
  out.delays.reserve(pulses.size());
  out.amplitudes.reserve(pulses.size());
  for (const auto& [k, a] : pulses) {
    out.delays.push_back(k);
    out.amplitudes.push_back(a / sum);
  }
  out.min_amplitude = *std::min_element(out.amplitudes.begin(), out.amplitudes.end());
  out.residual = discrete_residual(out, shaper.omega, shaper.zeta);
  return out;
}

double discrete_residual(const DiscreteShaper& shaper, double omega, double zeta) {
  return residual_vibration(shaper.to_shaper(), omega, zeta);
}

GridP1 adjust_p1_to_grid(double omega, double zeta, double p1, double ts) {
  require_mode(omega, zeta);
  require_finite_positive(ts, "ts");
  if (!std::isfinite(p1) || p1 < -1.0 || p1 > 1.0)
    throw InputError(at_field("p1"), "expected p1 in [-1, 1], got " + num(p1));
  const double wd = damped_frequency(omega, zeta);
  const double pi = std::numbers::pi;
  const auto p1_of = [&](double m) { return 3.0 * (pi - wd * m * ts) / (2.0 * pi); };
  // Admissible m: p1_of(m) in [-1, 1] <=> π/(3ω_d) <= m ts <= 5π/(3ω_d) (tolerance for exact ends).
  constexpr double kEdge = 1e-12;
  const double m_low = std::ceil(pi / (3.0 * wd * ts) * (1.0 - kEdge));
  const double m_high = std::floor(5.0 * pi / (3.0 * wd * ts) * (1.0 + kEdge));
  if (m_high < std::max(1.0, m_low))
    throw InputError(at_field("ts"), "sample period " + num(ts) +
                                         " s is longer than every ZV4 pulse spacing for omega = " + num(omega) +
                                         " rad/s, zeta = " + num(zeta) + " ([" + num(pi / (3.0 * wd)) + ", " +
                                         num(5.0 * pi / (3.0 * wd)) + "] s)");
  const double m_requested = (pi - p1 * 2.0 * pi / 3.0) / (wd * ts);
  const double below = std::clamp(std::floor(m_requested), std::max(1.0, m_low), m_high);
  const double above = std::clamp(std::ceil(m_requested), std::max(1.0, m_low), m_high);
  const double m = std::abs(p1_of(below) - p1) < std::abs(p1_of(above) - p1) ? below : above;
  GridP1 out;
  out.samples = static_cast<std::size_t>(m);
  out.spacing = m * ts;
  out.p1 = std::clamp(p1_of(m), -1.0, 1.0);
  return out;
}

Shaper zv4_on_grid(double omega, double zeta, const Zv4Parameters& parameters, double ts) {
  const GridP1 grid = adjust_p1_to_grid(omega, zeta, parameters.p1, ts);
  Zv4Parameters adjusted = parameters;
  adjusted.p1 = grid.p1;
  if (adjusted.p1 != 0.0) adjusted.p3 = 0.0;  // p3 exists only in the p1 = 0 branch (C6.2)
  Shaper shaper = zv4_shaper(omega, zeta, adjusted);
  // The formulas give t_i = i T up to rounding; put them exactly on the grid they were made for.
  for (double& t : shaper.times) t = std::round(t / ts) * ts;
  return shaper;
}

}  // namespace servotwin::shaping
