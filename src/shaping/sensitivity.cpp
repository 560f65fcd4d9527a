#include "servotwin/shaping/sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "servotwin/core/error.hpp"
#include "shaper_checks.hpp"
#include "servotwin/shaping/smoothing.hpp"

namespace servotwin::shaping {
namespace {

void check_mode(double omega, double zeta, const char* omega_name, const char* zeta_name) {
  if (!std::isfinite(omega) || omega < 0.0)
    throw core::InputError(core::at_field(omega_name),
                           "expected a finite frequency >= 0 rad/s, got " + detail::show(omega));
  detail::check_damping(zeta, zeta_name);
}

void check_shaper(const Shaper& shaper) {
  if (shaper.times.empty() || shaper.times.size() != shaper.amplitudes.size())
    throw core::InputError(core::at_field("shaper"),
                           "expected as many impulse times as amplitudes (at least one), got " +
                               std::to_string(shaper.times.size()) + " and " + std::to_string(shaper.amplitudes.size()));
}

// V without argument checks: the inner loop of curves and bandwidth searches.
double vibration(const Shaper& shaper, double omega, double zeta) noexcept {
  const double decay = zeta * omega;
  const double omega_d = omega * std::sqrt(1.0 - zeta * zeta);
  const double t_last = shaper.times.back();
  double c = 0.0;
  double s = 0.0;
  double sum = 0.0;
  for (std::size_t i = 0; i < shaper.times.size(); ++i) {
    const double w = shaper.amplitudes[i] * std::exp(-decay * (t_last - shaper.times[i]));
    const double phase = omega_d * shaper.times[i];
    c += w * std::cos(phase);
    s += w * std::sin(phase);
    sum += shaper.amplitudes[i];
  }
  return std::hypot(c, s) / sum;
}

// Bisection for the crossing of V = level between a (V <= level) and b (V > level).
double refine_edge(const Shaper& shaper, double zeta, double level, double inside, double outside) {
  for (int k = 0; k < 200 && std::abs(outside - inside) > 1e-12 * std::abs(inside); ++k) {
    const double mid = 0.5 * (inside + outside);
    (vibration(shaper, mid, zeta) <= level ? inside : outside) = mid;
  }
  return 0.5 * (inside + outside);
}

}  // namespace

double residual_vibration(const Shaper& shaper, double omega, double zeta) {
  check_mode(omega, zeta, "omega", "zeta");
  check_shaper(shaper);
  return vibration(shaper, omega, zeta);
}

std::vector<SensitivityPoint> sensitivity_curve(const Shaper& shaper, double omega_min, double omega_max, int count,
                                                double zeta) {
  check_mode(omega_min, zeta, "omega_min", "zeta");
  check_mode(omega_max, zeta, "omega_max", "zeta");
  check_shaper(shaper);
  if (!(omega_max > omega_min))
    throw core::InputError(core::at_field("omega_max"),
                           "expected omega_max > omega_min = " + detail::show(omega_min) + ", got " + detail::show(omega_max));
  if (count < 2) throw core::InputError(core::at_field("count"), "expected at least 2 points, got " + std::to_string(count));
  std::vector<SensitivityPoint> curve(static_cast<std::size_t>(count));
  const double step = (omega_max - omega_min) / (count - 1);
  for (int k = 0; k < count; ++k) {
    const double omega = k + 1 == count ? omega_max : omega_min + step * k;
    curve[static_cast<std::size_t>(k)] = {omega, vibration(shaper, omega, zeta)};
  }
  return curve;
}

std::vector<double> damping_sensitivity(const Shaper& shaper, const std::vector<double>& zetas) {
  check_shaper(shaper);
  std::vector<double> result;
  result.reserve(zetas.size());
  for (double zeta : zetas) {
    check_mode(shaper.omega, zeta, "shaper.omega", "zetas");
    result.push_back(vibration(shaper, shaper.omega, zeta));
  }
  return result;
}

InsensitiveBand insensitivity_band(const Shaper& shaper, double level, double zeta) {
  check_shaper(shaper);
  check_mode(shaper.omega, zeta, "shaper.omega", "zeta");
  if (!(shaper.omega > 0.0))
    throw core::InputError(core::at_field("shaper.omega"), "expected a design frequency > 0 rad/s");
  if (!(level > 0.0 && level < 1.0))
    throw core::InputError(core::at_field("level"), "expected a vibration level in (0, 1), got " + detail::show(level));
  const double omega0 = shaper.omega;
  // Start from the least vibration within ±10 % of the design frequency: EI-type shapers are
  // deliberately not zero at the design frequency but have zeros next to it.
  constexpr int kSeedPoints = 201;
  double seed = omega0;
  double seed_v = vibration(shaper, omega0, zeta);
  for (int k = 0; k < kSeedPoints; ++k) {
    const double omega = omega0 * (0.9 + 0.2 * k / (kSeedPoints - 1));
    const double v = vibration(shaper, omega, zeta);
    if (v < seed_v) {
      seed = omega;
      seed_v = v;
    }
  }
  if (seed_v > level)
    throw core::InputError(core::at_field("level"),
                           "the shaper's vibration exceeds " + detail::show(level) +
                               " everywhere within ±10 % of its design frequency (least " + detail::show(seed_v) +
                               "): the insensitive band is empty");
  // Scan outward in steps of 0.1 % of the design frequency (finer than any stop band's
  // structure for shapers up to a few hundred periods long), then bisect the crossing.
  const double step = 1e-3 * omega0;
  double low_inside = seed;
  double low = seed - step;
  while (low > 0.0 && vibration(shaper, low, zeta) <= level) {
    low_inside = low;
    low -= step;
  }
  const double omega_low = low <= 0.0 ? 0.0 : refine_edge(shaper, zeta, level, low_inside, low);
  double high_inside = seed;
  double high = seed + step;
  // V(ω) of a finite pulse train with positive damping does not stay below level forever; the
  // limit keeps a pathological shaper (e.g. all weight on one impulse) from looping.
  const double high_limit = 100.0 * omega0;
  while (high < high_limit && vibration(shaper, high, zeta) <= level) {
    high_inside = high;
    high += step;
  }
  const double omega_high = refine_edge(shaper, zeta, level, high_inside, high);
  return {omega_low, omega_high, (omega_high - omega_low) / omega0};
}

std::vector<ShaperComparisonRow> compare_shapers(const std::vector<Shaper>& shapers, const ComparisonOptions& options) {
  if (!(options.level > 0.0 && options.level < 1.0))
    throw core::InputError(core::at_field("level"),
                           "expected a vibration level in (0, 1), got " + detail::show(options.level));
  std::vector<ShaperComparisonRow> rows;
  rows.reserve(shapers.size());
  for (const Shaper& shaper : shapers) {
    ShaperComparisonRow row;
    row.type = shaper.type;
    row.duration_s = shaper.duration();
    row.residual_at_design = residual_vibration(shaper, shaper.omega, shaper.zeta);
    row.impulse_count = static_cast<int>(shaper.times.size());
    try {
      const InsensitiveBand band = insensitivity_band(shaper, options.level, shaper.zeta);
      row.band_width_normalized = band.normalized_width;
      row.band_low_ratio = band.omega_low / shaper.omega;
      row.band_high_ratio = band.omega_high / shaper.omega;
    } catch (const core::InputError&) {
      // An empty band is a legitimate property of a shaper in a comparison, reported as zero width.
    }
    row.smoothing = shaper_smoothing(shaper, options.accel, options.scv);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace servotwin::shaping
