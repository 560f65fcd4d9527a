#include "servotwin/shaping/selection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <fmt/format.h>
#include <limits>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/shaping/multimode.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/smoothing.hpp"
#include "shaper_checks.hpp"

namespace servotwin::shaping {

std::string to_string(SpectrumAxis axis) {
  switch (axis) {
    case SpectrumAxis::kX: return "x";
    case SpectrumAxis::kY: return "y";
    case SpectrumAxis::kZ: return "z";
    case SpectrumAxis::kSum: break;
  }
  return "xyz";
}

SpectrumAxis parse_spectrum_axis(const std::string& name, const std::string& field) {
  if (name == "x" || name == "X") return SpectrumAxis::kX;
  if (name == "y" || name == "Y") return SpectrumAxis::kY;
  if (name == "z" || name == "Z") return SpectrumAxis::kZ;
  if (name == "xyz" || name == "XYZ" || name == "all" || name == "sum") return SpectrumAxis::kSum;
  throw core::InputError(core::at_field(field), fmt::format("unknown axis '{}': expected x, y, z or xyz", name));
}

namespace {

// Klipper's suggested max_accel; 0 when no acceleration meets the target.
double suggested_max_accel(const Shaper& shaper, double max_smoothing, double scv) {
  return reachable_max_accel(shaper, max_smoothing, scv).value_or(0.0);
}

constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Step of the V(f/f_s) tables: linear interpolation error ≤ h²/8·max|V''| < 1e-5.
constexpr double kTableStep = 1.0 / 2048.0;
/// Table points between exact re-anchors of the complex recurrence (bounds rounding drift).
constexpr std::size_t kReanchorEvery = 256;
/// Table minima closer than this to the least value are re-scored exactly.
constexpr double kExactRescoreBand = 2e-5;

void require(bool ok, const std::string& field, const std::string& message) {
  if (!ok) throw core::InputError(core::at_field(field), message);
}

void check_positive(double value, const std::string& field) {
  require(std::isfinite(value) && value > 0.0, field, fmt::format("expected a finite value > 0, got {}", value));
}

void check_measure(const VibrationMeasure& measure) {
  require(!measure.test_dampings.empty(), "test_dampings", "expected at least one test damping ratio");
  for (double z : measure.test_dampings)
    require(std::isfinite(z) && z >= 0.0 && z < 1.0, "test_dampings",
            fmt::format("expected damping ratios in [0, 1), got {}", z));
  require(std::isfinite(measure.threshold_fraction) && measure.threshold_fraction >= 0.0 &&
              measure.threshold_fraction < 1.0,
          "threshold_fraction", fmt::format("expected a value in [0, 1), got {}", measure.threshold_fraction));
}

/// θ and the denominator Σ max(psd − θ, 0) of the measure.
struct Threshold {
  double theta = 0.0;
  double all = 0.0;
};

Threshold threshold_of(const PreparedSpectrum& s, const VibrationMeasure& measure) {
  const double peak = *std::max_element(s.psd.begin(), s.psd.end());
  Threshold t;
  t.theta = peak * measure.threshold_fraction;
  for (double p : s.psd) t.all += std::max(p - t.theta, 0.0);
  return t;
}

// ---------------------------------------------------------------------------------------------
// Single-mode shapers at unit frequency: at a fixed design damping the impulse times scale as 1/f.

struct UnitShaper {
  ShaperType type = ShaperType::kZv;
  std::string name;
  double zeta = 0.0;
  std::vector<double> times;  ///< at 1 Hz [s] (= in periods)
  std::vector<double> amplitudes;
};

UnitShaper unit_shaper(ShaperType type, double zeta) {
  const Shaper s = design_shaper(type, kTwoPi, zeta);
  return {type, std::string(to_string(type)), zeta, s.times, s.amplitudes};
}

Shaper scaled(const UnitShaper& u, double freq_hz) {
  Shaper s;
  s.type = u.name;
  s.omega = kTwoPi * freq_hz;
  s.zeta = u.zeta;
  s.amplitudes = u.amplitudes;
  s.times.resize(u.times.size());
  for (std::size_t i = 0; i < u.times.size(); ++i) s.times[i] = u.times[i] / freq_hz;
  return s;
}

/// V(r, ζ_t) of a unit shaper for r = f/f_s on [0, r_max], one row per test damping.
struct VibrationTable {
  std::vector<std::vector<double>> rows;

  [[nodiscard]] double at(std::size_t row, double r) const noexcept {
    const std::vector<double>& v = rows[row];
    const double x = r / kTableStep;
    const auto k = static_cast<std::size_t>(x);
    if (k + 1 >= v.size()) return v.back();
    const double w = x - static_cast<double>(k);
    return v[k] + w * (v[k + 1] - v[k]);
  }
};

VibrationTable vibration_table(const UnitShaper& u, const std::vector<double>& dampings, double r_max) {
  const auto count = static_cast<std::size_t>(std::ceil(r_max / kTableStep)) + 2;
  const std::size_t n = u.times.size();
  double sum_a = 0.0;
  for (double a : u.amplitudes) sum_a += a;
  const double t_last = u.times.back();
  VibrationTable table;
  std::vector<std::complex<double>> rate(n), step(n), term(n);
  for (double zt : dampings) {
    std::vector<double> row(count);
    const double wd = std::sqrt(1.0 - zt * zt);
    for (std::size_t i = 0; i < n; ++i) {
      // term_i(r) = A_i exp(2π r (−ζ(τ_n − τ_i) + j√(1−ζ²) τ_i)): geometric in r on a uniform grid.
      rate[i] = kTwoPi * std::complex<double>(-zt * (t_last - u.times[i]), wd * u.times[i]);
      step[i] = std::exp(rate[i] * kTableStep);
    }
    for (std::size_t k = 0; k < count; ++k) {
      if (k % kReanchorEvery == 0)
        for (std::size_t i = 0; i < n; ++i)
          term[i] = u.amplitudes[i] * std::exp(rate[i] * (static_cast<double>(k) * kTableStep));
      std::complex<double> sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        sum += term[i];
        term[i] *= step[i];
      }
      row[k] = std::abs(sum) / sum_a;
    }
    table.rows.push_back(std::move(row));
  }
  return table;
}

/// Remaining vibrations from per-bin vibration ratios given by `v(row, bin)`.
template <typename VibrationOf>
double remaining_from(const PreparedSpectrum& s, const Threshold& t, std::size_t rows, VibrationOf v) {
  if (t.all <= 0.0) return 0.0;
  double worst = 0.0;
  for (std::size_t row = 0; row < rows; ++row) {
    double remaining = 0.0;
    for (std::size_t k = 0; k < s.psd.size(); ++k) remaining += std::max(s.psd[k] * v(row, k) - t.theta, 0.0);
    worst = std::max(worst, remaining / t.all);
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// Smoothing of a two-factor convolution without building it (smoothing.hpp's definition).

double smoothing_of_pair(const UnitShaper& a, double fa, const UnitShaper& b, double fb, double accel, double scv) {
  double sum_a = 0.0, sum_b = 0.0, ca = 0.0, cb = 0.0;
  for (std::size_t i = 0; i < a.times.size(); ++i) {
    sum_a += a.amplitudes[i];
    ca += a.amplitudes[i] * a.times[i] / fa;
  }
  for (std::size_t j = 0; j < b.times.size(); ++j) {
    sum_b += b.amplitudes[j];
    cb += b.amplitudes[j] * b.times[j] / fb;
  }
  const double centroid = ca / sum_a + cb / sum_b;  // centroids of a convolution add
  const double total = sum_a * sum_b;
  double x = 0.0, y = 0.0, reversal = 0.0;
  for (std::size_t i = 0; i < a.times.size(); ++i)
    for (std::size_t j = 0; j < b.times.size(); ++j) {
      const double amp = a.amplitudes[i] * b.amplitudes[j];
      const double tau = a.times[i] / fa + b.times[j] / fb - centroid;
      reversal += amp * 0.5 * accel * tau * tau;
      if (tau >= 0.0)
        x += amp * (scv + 0.5 * accel * tau) * tau;
      else
        y += amp * (scv - 0.5 * accel * tau) * (-tau);
    }
  return std::max(std::hypot(x, y), reversal) / total;
}

// ---------------------------------------------------------------------------------------------
// The choice rule shared by both paths.

struct Point {
  std::size_t group = 0;        ///< family index (or the two-mode group)
  std::array<double, 2> freq{};  ///< factor frequencies [Hz] (second 0 for single-mode)
  std::array<std::size_t, 2> unit{};
  double vibrations = 0.0;
  double smoothing = 0.0;
  bool exact = false;
};

/// Least vibrations; within `tolerance` of it, least smoothing. `rescore` replaces a point's
/// tabulated vibrations by the exact value (points near the minimum only).
template <typename Rescore>
std::size_t choose(std::vector<Point>& pool, const std::vector<std::size_t>& members, double tolerance,
                   Rescore rescore) {
  double least = std::numeric_limits<double>::infinity();
  for (std::size_t m : members) least = std::min(least, pool[m].vibrations);
  for (std::size_t m : members)
    if (!pool[m].exact && pool[m].vibrations <= least + kExactRescoreBand) rescore(pool[m]);
  double least_exact = std::numeric_limits<double>::infinity();
  for (std::size_t m : members) least_exact = std::min(least_exact, pool[m].vibrations);
  std::size_t best = members.front();
  bool found = false;
  for (std::size_t m : members) {
    if (pool[m].vibrations > least_exact + tolerance) continue;
    if (!found || pool[m].smoothing < pool[best].smoothing ||
        (pool[m].smoothing == pool[best].smoothing && pool[m].vibrations < pool[best].vibrations)) {
      best = m;
      found = true;
    }
  }
  if (!pool[best].exact) rescore(pool[best]);
  return best;
}

std::string percent(double v) { return fmt::format("{:.1f} %", 100.0 * v); }

std::string describe(const ShaperCandidate& c) {
  std::string freqs;
  for (std::size_t i = 0; i < c.freq_hz.size(); ++i) freqs += fmt::format("{}{:.1f}", i ? "+" : "", c.freq_hz[i]);
  return fmt::format("{} @ {} Hz", c.name, freqs);
}

void add_reasons(ShaperSelection& result, const std::string& limit_text, double tolerance, bool lower_is_better_label) {
  const ShaperCandidate& w = result.recommended;
  result.reasons.push_back(fmt::format("{}: {} {}, smoothing {:.3f}, max_accel ≤ {:.0f}, delay {:.1f} ms.",
                                       describe(w), lower_is_better_label ? "worst residual" : "remaining vibrations",
                                       percent(w.vibrations), w.smoothing, w.max_accel, 1e3 * w.duration_s));
  result.reasons.push_back("Limit: " + limit_text + ".");
  const ShaperCandidate* least = &w;
  for (const ShaperCandidate& c : result.alternatives)
    if (c.vibrations < least->vibrations) least = &c;
  if (least == &w || least->vibrations >= w.vibrations)
    result.reasons.push_back("It leaves the least vibration of all shapers within the limit.");
  else
    result.reasons.push_back(fmt::format(
        "The least vibration within the limit is {} ({}); {} is within {:.1f} points of it and smooths less "
        "({:.3f} vs {:.3f}), so it wins (differences below the tolerance are not resolvable).",
        percent(least->vibrations), describe(*least), w.name, 100.0 * tolerance, w.smoothing, least->smoothing));
  for (const ShaperCandidate& c : result.alternatives) {
    if (c.name == w.name && c.freq_hz == w.freq_hz) continue;
    const double dv = c.vibrations - w.vibrations;
    std::string verdict;
    if (dv > tolerance)
      verdict = fmt::format("leaves {:.1f} points more vibration", 100.0 * dv);
    else if (c.smoothing > w.smoothing)
      verdict = fmt::format("about as much vibration but {:.0f} % more smoothing",
                            100.0 * (c.smoothing / w.smoothing - 1.0));
    else
      verdict = "equivalent";
    result.reasons.push_back(fmt::format("Runner-up {}: {}, smoothing {:.3f} — {}.", describe(c),
                                         percent(c.vibrations), c.smoothing, verdict));
  }
}

void sort_alternatives(std::vector<ShaperCandidate>& v) {
  std::stable_sort(v.begin(), v.end(), [](const ShaperCandidate& a, const ShaperCandidate& b) {
    if (a.vibrations != b.vibrations) return a.vibrations < b.vibrations;
    return a.smoothing < b.smoothing;
  });
}

/// Grid of multiples of `step` in [lo, hi] (Klipper's grid when lo is a multiple of 0.2 Hz).
std::vector<double> frequency_grid(double lo, double hi, double step) {
  std::vector<double> grid;
  const auto first = static_cast<long long>(std::ceil(lo / step - 1e-9));
  for (long long k = first;; ++k) {
    const double f = static_cast<double>(k) * step;
    if (f > hi + 1e-9) break;
    grid.push_back(f);
  }
  return grid;
}

}  // namespace

// -------------------------------------------------------------------------------------------------

std::vector<double> normalize_psd(const std::vector<double>& freq_hz, const std::vector<double>& psd,
                                  double min_freq_hz) {
  require(freq_hz.size() == psd.size(), "psd",
          fmt::format("expected as many PSD values as frequencies ({}), got {}", freq_hz.size(), psd.size()));
  std::vector<double> out(psd.size());
  for (std::size_t k = 0; k < psd.size(); ++k) {
    const double f = freq_hz[k] + 0.1;
    out[k] = psd[k] / f;
    if (freq_hz[k] < 2.0 * min_freq_hz) {
      const double q = 2.0 * min_freq_hz / f;
      out[k] *= std::exp(1.0 - q * q);  // removes low-frequency noise (Klipper's taper)
    }
  }
  return out;
}

PreparedSpectrum prepare_spectrum(const Spectrum& spectrum, SpectrumAxis axis, double max_freq_hz) {
  check_positive(max_freq_hz, "max_psd_freq_hz");
  const std::vector<double>& psd = spectrum.psd(axis);
  const std::string column = "psd_" + to_string(axis);
  const std::string where = spectrum.source.empty() ? column : spectrum.source + ": " + column;
  require(psd.size() == spectrum.freq_hz.size(), where,
          fmt::format("expected {} values (one per frequency), got {}", spectrum.freq_hz.size(), psd.size()));
  PreparedSpectrum out;
  for (std::size_t k = 0; k < psd.size(); ++k) {
    const double f = spectrum.freq_hz[k];
    require(std::isfinite(f) && f >= 0.0, where, fmt::format("frequency {} Hz (bin {}): expected finite ≥ 0", f, k));
    require(k == 0 || f > spectrum.freq_hz[k - 1], where,
            fmt::format("frequency {} Hz (bin {}) does not increase", f, k));
    require(std::isfinite(psd[k]) && psd[k] >= 0.0, where,
            fmt::format("power {} at {} Hz: expected a finite value ≥ 0", psd[k], f));
    if (f > max_freq_hz) break;
    out.freq_hz.push_back(f);
    out.psd.push_back(psd[k]);
  }
  require(out.freq_hz.size() >= 3, where, fmt::format("expected at least 3 bins up to {} Hz", max_freq_hz));
  if (!spectrum.normalized) out.psd = normalize_psd(out.freq_hz, out.psd);
  require(*std::max_element(out.psd.begin(), out.psd.end()) > 0.0, where, "the PSD is zero everywhere");
  return out;
}

double remaining_vibrations(const Shaper& shaper, const PreparedSpectrum& spectrum, const VibrationMeasure& measure) {
  check_measure(measure);
  require(!spectrum.psd.empty() && spectrum.psd.size() == spectrum.freq_hz.size(), "spectrum",
          "expected a non-empty PSD with one value per frequency");
  const Threshold t = threshold_of(spectrum, measure);
  return remaining_from(spectrum, t, measure.test_dampings.size(), [&](std::size_t row, std::size_t k) {
    return residual_vibration(shaper, kTwoPi * spectrum.freq_hz[k], measure.test_dampings[row]);
  });
}

std::vector<SpectrumPeak> find_spectrum_peaks(const PreparedSpectrum& s, double min_fraction, int max_peaks,
                                              double min_freq_hz) {
  const std::size_t n = s.psd.size();
  if (n < 3 || max_peaks <= 0) return {};
  const double top = *std::max_element(s.psd.begin(), s.psd.end());
  std::vector<std::size_t> maxima;
  for (std::size_t k = 0; k < n; ++k) {
    const bool left = k == 0 || s.psd[k] > s.psd[k - 1];
    const bool right = k + 1 == n || s.psd[k] >= s.psd[k + 1];
    if (left && right && s.psd[k] >= min_fraction * top && s.freq_hz[k] > min_freq_hz) maxima.push_back(k);
  }
  // A maximum is kept when, towards every larger maximum, the PSD dips below half of its height.
  std::vector<SpectrumPeak> peaks;
  for (std::size_t m : maxima) {
    bool separated = true;
    for (std::size_t other : maxima) {
      if (other == m || s.psd[other] < s.psd[m] || (s.psd[other] == s.psd[m] && other > m)) continue;
      const std::size_t lo = std::min(other, m), hi = std::max(other, m);
      const double valley = *std::min_element(s.psd.begin() + static_cast<std::ptrdiff_t>(lo),
                                              s.psd.begin() + static_cast<std::ptrdiff_t>(hi) + 1);
      if (valley > 0.5 * s.psd[m]) separated = false;
    }
    if (separated) peaks.push_back({s.freq_hz[m], s.psd[m]});
  }
  std::sort(peaks.begin(), peaks.end(), [](const SpectrumPeak& a, const SpectrumPeak& b) { return a.psd > b.psd; });
  if (peaks.size() > static_cast<std::size_t>(max_peaks)) peaks.resize(static_cast<std::size_t>(max_peaks));
  return peaks;
}

// -------------------------------------------------------------------------------------------------

namespace {

void check_options(const SpectrumSelectionOptions& o) {
  require(!o.families.empty(), "families", "expected at least one shaper family");
  for (ShaperType t : o.families)
    require(t != ShaperType::kZv4, "families", "zv4 needs its p-parameters and cannot be auto-tuned here");
  detail::check_damping(o.design_zeta, "design_zeta");
  check_measure(o.measure);
  check_positive(o.min_shaper_freq_hz, "min_shaper_freq_hz");
  check_positive(o.freq_step_hz, "freq_step_hz");
  require(std::isfinite(o.max_shaper_freq_hz) && o.max_shaper_freq_hz > o.min_shaper_freq_hz, "max_shaper_freq_hz",
          fmt::format("expected a value > min_shaper_freq_hz {}, got {}", o.min_shaper_freq_hz, o.max_shaper_freq_hz));
  if (o.max_smoothing) check_positive(*o.max_smoothing, "max_smoothing");
  if (o.max_delay_s) check_positive(*o.max_delay_s, "max_delay_s");
  check_positive(o.min_max_accel, "min_max_accel");
  check_positive(o.accel, "accel");
  require(std::isfinite(o.scv) && o.scv >= 0.0, "scv", fmt::format("expected a finite value ≥ 0, got {}", o.scv));
  check_positive(o.max_accel_smoothing, "max_accel_smoothing");
  require(std::isfinite(o.vibration_tolerance) && o.vibration_tolerance >= 0.0, "vibration_tolerance",
          fmt::format("expected a finite value ≥ 0, got {}", o.vibration_tolerance));
}

/// The smoothing and delay limits of the spectrum path, as one feasibility test.
struct Limits {
  const SpectrumSelectionOptions& o;
  [[nodiscard]] bool admits(double smoothing_at_accel, double smoothing_at_floor, double duration) const {
    if (o.max_smoothing ? smoothing_at_accel > *o.max_smoothing * (1.0 + 1e-12)
                        : smoothing_at_floor > o.max_accel_smoothing * (1.0 + 1e-12))
      return false;
    return !(o.max_delay_s && duration > *o.max_delay_s * (1.0 + 1e-12));
  }
  [[nodiscard]] std::string text() const {
    std::string t = o.max_smoothing ? fmt::format("smoothing ≤ {} (accel {}, scv {})", *o.max_smoothing, o.accel, o.scv)
                                    : fmt::format("suggested max_accel ≥ {} (smoothing {} at scv {})", o.min_max_accel,
                                                  o.max_accel_smoothing, o.scv);
    if (o.max_delay_s) t += fmt::format(", delay ≤ {} ms", 1e3 * *o.max_delay_s);
    return t;
  }
};

}  // namespace

ShaperSelection select_shaper_from_spectrum(const Spectrum& spectrum, const SpectrumSelectionOptions& o) {
  check_options(o);
  const PreparedSpectrum s = prepare_spectrum(spectrum, o.axis, o.max_psd_freq_hz);
  const Threshold threshold = threshold_of(s, o.measure);
  const std::size_t rows = o.measure.test_dampings.size();
  const Limits limits{o};

  std::vector<UnitShaper> units;
  for (ShaperType t : o.families) units.push_back(unit_shaper(t, o.design_zeta));
  const std::vector<double> grid = frequency_grid(o.min_shaper_freq_hz, o.max_shaper_freq_hz, o.freq_step_hz);

  auto smoothing_pair = [&](const Shaper& sh) {
    return std::make_pair(shaper_smoothing(sh, o.accel, o.scv), shaper_smoothing(sh, o.min_max_accel, o.scv));
  };

  // Feasible start of each family: smoothing and delay decrease with the shaper frequency.
  std::vector<std::size_t> start(units.size(), grid.size());
  double least_smoothing = std::numeric_limits<double>::infinity(), least_delay = least_smoothing;
  double lowest_start_hz = std::numeric_limits<double>::infinity();
  for (std::size_t u = 0; u < units.size(); ++u) {
    for (std::size_t g = 0; g < grid.size(); ++g) {
      const Shaper sh = scaled(units[u], grid[g]);
      const auto [sm, sm_floor] = smoothing_pair(sh);
      if (limits.admits(sm, sm_floor, sh.duration())) {
        start[u] = g;
        lowest_start_hz = std::min(lowest_start_hz, grid[g]);
        break;
      }
    }
    const Shaper fastest = scaled(units[u], grid.back());
    least_smoothing = std::min(least_smoothing, shaper_smoothing(fastest, o.accel, o.scv));
    least_delay = std::min(least_delay, fastest.duration());
  }
  if (!std::isfinite(lowest_start_hz))
    throw core::InputError(core::at_field(o.max_smoothing ? "max_smoothing" : o.max_delay_s ? "max_delay_s" : "min_max_accel"),
                           fmt::format("no shaper up to {} Hz satisfies {}; the least reachable smoothing is {:.4f} "
                                       "and the least delay {:.2f} ms",
                                       o.max_shaper_freq_hz, limits.text(), least_smoothing, 1e3 * least_delay));

  const double r_max = s.freq_hz.back() / lowest_start_hz;
  std::vector<VibrationTable> tables;
  for (const UnitShaper& u : units) tables.push_back(vibration_table(u, o.measure.test_dampings, r_max));

  std::vector<Point> pool;
  std::vector<std::vector<std::size_t>> groups(units.size());
  for (std::size_t u = 0; u < units.size(); ++u) {
    for (std::size_t g = start[u]; g < grid.size(); ++g) {
      const double f = grid[g];
      const Shaper sh = scaled(units[u], f);
      const auto [sm, sm_floor] = smoothing_pair(sh);
      if (!limits.admits(sm, sm_floor, sh.duration())) continue;
      Point p;
      p.group = u;
      p.freq = {f, 0.0};
      p.unit = {u, 0};
      p.smoothing = sm;
      p.vibrations = remaining_from(s, threshold, rows, [&](std::size_t row, std::size_t k) {
        return tables[u].at(row, s.freq_hz[k] / f);
      });
      groups[u].push_back(pool.size());
      pool.push_back(p);
    }
  }

  // Two-mode shapers: one factor per separated peak, frequencies by coordinate descent.
  ShaperSelection result;
  result.peaks = find_spectrum_peaks(s);
  const std::size_t two_mode_group = units.size();
  std::vector<std::size_t> two_mode_members;
  std::vector<UnitShaper> mm_units;
  std::vector<VibrationTable> mm_tables;
  if (o.multi_mode && result.peaks.size() >= 2) {
    for (ShaperType t : o.multi_mode_families) mm_units.push_back(unit_shaper(t, o.design_zeta));
    const double lowest_peak = std::min(result.peaks[0].freq_hz, result.peaks[1].freq_hz);
    const double r_mm = s.freq_hz.back() / std::max(0.6 * lowest_peak, o.min_shaper_freq_hz);
    for (const UnitShaper& u : mm_units) mm_tables.push_back(vibration_table(u, o.measure.test_dampings, r_mm));
    for (std::size_t pa = 0; pa < result.peaks.size(); ++pa)
      for (std::size_t pb = pa + 1; pb < result.peaks.size(); ++pb) {
        const double peak_a = result.peaks[pa].freq_hz, peak_b = result.peaks[pb].freq_hz;
        const std::vector<double> win_a = frequency_grid(std::max(0.6 * peak_a, o.min_shaper_freq_hz),
                                                         std::min(1.6 * peak_a, o.max_shaper_freq_hz), o.freq_step_hz);
        const std::vector<double> win_b = frequency_grid(std::max(0.6 * peak_b, o.min_shaper_freq_hz),
                                                         std::min(1.6 * peak_b, o.max_shaper_freq_hz), o.freq_step_hz);
        if (win_a.empty() || win_b.empty()) continue;
        for (std::size_t ua = 0; ua < mm_units.size(); ++ua)
          for (std::size_t ub = 0; ub < mm_units.size(); ++ub) {
            auto evaluate = [&](double fa, double fb, bool keep) {
              const double sm = smoothing_of_pair(mm_units[ua], fa, mm_units[ub], fb, o.accel, o.scv);
              const double sm_floor = smoothing_of_pair(mm_units[ua], fa, mm_units[ub], fb, o.min_max_accel, o.scv);
              const double duration = mm_units[ua].times.back() / fa + mm_units[ub].times.back() / fb;
              if (!limits.admits(sm, sm_floor, duration)) return std::numeric_limits<double>::infinity();
              const double v = remaining_from(s, threshold, rows, [&](std::size_t row, std::size_t k) {
                return mm_tables[ua].at(row, s.freq_hz[k] / fa) * mm_tables[ub].at(row, s.freq_hz[k] / fb);
              });
              if (keep) {
                Point p;
                p.group = two_mode_group;
                p.freq = {fa, fb};
                p.unit = {ua, ub};
                p.smoothing = sm;
                p.vibrations = v;
                two_mode_members.push_back(pool.size());
                pool.push_back(p);
              }
              return v;
            };
            double fa = win_a[win_a.size() / 2], fb = win_b[win_b.size() / 2];
            for (int round = 0; round < 2; ++round) {
              const bool last = round == 1;
              double best = std::numeric_limits<double>::infinity();
              for (double f : win_a) {
                const double v = evaluate(f, fb, last);
                if (v < best) best = v, fa = f;
              }
              best = std::numeric_limits<double>::infinity();
              for (double f : win_b) {
                const double v = evaluate(fa, f, last);
                if (v < best) best = v, fb = f;
              }
            }
          }
      }
  }

  auto shaper_of = [&](const Point& p) {
    if (p.group == two_mode_group)
      return convolve_shapers(scaled(mm_units[p.unit[0]], p.freq[0]), scaled(mm_units[p.unit[1]], p.freq[1]), 1e-12);
    return scaled(units[p.unit[0]], p.freq[0]);
  };
  auto rescore = [&](Point& p) {
    p.vibrations = remaining_vibrations(shaper_of(p), s, o.measure);
    p.exact = true;
  };
  auto candidate_of = [&](const Point& p) {
    ShaperCandidate c;
    c.shaper = shaper_of(p);
    if (p.group == two_mode_group) {
      c.name = mm_units[p.unit[0]].name + "+" + mm_units[p.unit[1]].name;
      c.freq_hz = {p.freq[0], p.freq[1]};
    } else {
      c.name = units[p.unit[0]].name;
      c.freq_hz = {p.freq[0]};
    }
    c.vibrations = p.vibrations;
    c.smoothing = p.smoothing;
    c.max_accel = suggested_max_accel(c.shaper, o.max_accel_smoothing, o.scv);
    c.duration_s = c.shaper.duration();
    c.vibrations_assumed_damping = std::numeric_limits<double>::quiet_NaN();
    return c;
  };

  std::vector<std::size_t> everything;
  for (std::size_t i = 0; i < pool.size(); ++i) everything.push_back(i);
  const std::size_t winner = choose(pool, everything, o.vibration_tolerance, rescore);
  result.recommended = candidate_of(pool[winner]);
  for (const std::vector<std::size_t>& members : groups) {
    if (members.empty()) continue;
    result.alternatives.push_back(candidate_of(pool[choose(pool, members, o.vibration_tolerance, rescore)]));
  }
  if (!two_mode_members.empty())
    result.alternatives.push_back(candidate_of(pool[choose(pool, two_mode_members, o.vibration_tolerance, rescore)]));
  // The winner's own group choice can differ from the global one; make sure the winner is listed.
  bool listed = false;
  for (const ShaperCandidate& c : result.alternatives)
    listed = listed || (c.name == result.recommended.name && c.freq_hz == result.recommended.freq_hz);
  if (!listed) result.alternatives.push_back(result.recommended);
  sort_alternatives(result.alternatives);
  add_reasons(result, limits.text(), o.vibration_tolerance, false);
  if (result.peaks.size() >= 2) {
    std::string list;
    for (const SpectrumPeak& p : result.peaks) list += fmt::format("{}{:.1f}", list.empty() ? "" : ", ", p.freq_hz);
    result.reasons.push_back(fmt::format("The spectrum has {} separated resonance peaks ({} Hz); two-mode shapers "
                                         "(one factor per peak) were considered{}.",
                                         result.peaks.size(), list,
                                         o.multi_mode ? "" : " — disabled by the options"));
  }
  return result;
}

// -------------------------------------------------------------------------------------------------

ShaperSelection select_shaper_from_model(const std::vector<KnownMode>& modes, const ModelSelectionOptions& o) {
  require(!modes.empty(), "modes", "expected at least one resonance mode");
  for (std::size_t i = 0; i < modes.size(); ++i) {
    check_positive(modes[i].freq_hz, fmt::format("modes[{}].freq_hz", i));
    detail::check_damping(modes[i].zeta, fmt::format("modes[{}].zeta", i));
  }
  require(!o.families.empty(), "families", "expected at least one shaper family");
  require(std::isfinite(o.freq_uncertainty) && o.freq_uncertainty >= 0.0 && o.freq_uncertainty < 0.5,
          "freq_uncertainty", fmt::format("expected a relative value in [0, 0.5), got {}", o.freq_uncertainty));
  require(std::isfinite(o.zeta_uncertainty) && o.zeta_uncertainty >= 0.0 && o.zeta_uncertainty < 1.0,
          "zeta_uncertainty", fmt::format("expected a value in [0, 1), got {}", o.zeta_uncertainty));
  require(o.band_points >= 1, "band_points", fmt::format("expected ≥ 1, got {}", o.band_points));
  if (o.max_smoothing) check_positive(*o.max_smoothing, "max_smoothing");
  if (o.max_delay_s) check_positive(*o.max_delay_s, "max_delay_s");
  check_positive(o.accel, "accel");
  check_positive(o.max_accel_smoothing, "max_accel_smoothing");
  detail::check_damping(o.assumed_zeta, "assumed_zeta");

  // Worst residual over every mode, its frequency band and its damping range.
  auto worst_residual = [&](const Shaper& sh) {
    double worst = 0.0;
    for (const KnownMode& m : modes) {
      const std::array<double, 3> zetas = {std::max(0.0, m.zeta - o.zeta_uncertainty), m.zeta,
                                           std::min(0.99, m.zeta + o.zeta_uncertainty)};
      for (int k = 0; k < o.band_points; ++k) {
        const double x = o.band_points == 1 ? 0.0 : -1.0 + 2.0 * k / static_cast<double>(o.band_points - 1);
        const double omega = kTwoPi * m.freq_hz * (1.0 + o.freq_uncertainty * x);
        for (double z : zetas) worst = std::max(worst, residual_vibration(sh, omega, z));
      }
    }
    return worst;
  };
  auto design_all = [&](ShaperType t, bool assumed) {
    std::vector<Shaper> factors;
    for (const KnownMode& m : modes) factors.push_back(design_shaper(t, kTwoPi * m.freq_hz, assumed ? o.assumed_zeta : m.zeta));
    return convolve_shapers(factors, 1e-12);
  };

  ShaperSelection result;
  std::vector<ShaperCandidate> candidates;
  std::vector<std::string> skipped;
  for (ShaperType t : o.families) {
    if (t == ShaperType::kZv4) continue;
    ShaperCandidate c;
    try {
      c.shaper = design_all(t, false);
    } catch (const core::InputError& e) {
      skipped.push_back(fmt::format("{} (not designable for this damping: {})", to_string(t), e.reason()));
      continue;
    }
    c.shaper.type = modes.size() == 1 ? std::string(to_string(t)) : "multi";
    c.name = std::string(to_string(t));
    for (const KnownMode& m : modes) c.freq_hz.push_back(m.freq_hz);
    c.vibrations = worst_residual(c.shaper);
    c.smoothing = shaper_smoothing(c.shaper, o.accel, o.scv);
    c.max_accel = suggested_max_accel(c.shaper, o.max_accel_smoothing, o.scv);
    c.duration_s = c.shaper.duration();
    try {
      c.vibrations_assumed_damping = worst_residual(design_all(t, true));
    } catch (const core::InputError&) {
      c.vibrations_assumed_damping = std::numeric_limits<double>::quiet_NaN();
    }
    if (o.max_smoothing && c.smoothing > *o.max_smoothing) {
      skipped.push_back(fmt::format("{} (smoothing {:.3f} over the limit)", c.name, c.smoothing));
      continue;
    }
    if (o.max_delay_s && c.duration_s > *o.max_delay_s) {
      skipped.push_back(fmt::format("{} (delay {:.2f} ms over the limit)", c.name, 1e3 * c.duration_s));
      continue;
    }
    candidates.push_back(std::move(c));
  }
  if (candidates.empty()) {
    std::string list;
    for (const std::string& s : skipped) list += (list.empty() ? "" : "; ") + s;
    throw core::InputError(core::at_field(o.max_smoothing ? "max_smoothing" : "max_delay_s"),
                           "no shaper family satisfies the limits: " + list);
  }
  std::vector<Point> pool;
  std::vector<std::size_t> members;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    Point p;
    p.group = i;
    p.vibrations = candidates[i].vibrations;
    p.smoothing = candidates[i].smoothing;
    p.exact = true;
    members.push_back(pool.size());
    pool.push_back(p);
  }
  const std::size_t winner = choose(pool, members, o.vibration_tolerance, [](Point&) {});
  result.recommended = candidates[pool[winner].group];
  result.alternatives = candidates;
  sort_alternatives(result.alternatives);
  std::string limit = o.max_smoothing ? fmt::format("smoothing ≤ {}", *o.max_smoothing) : std::string("none on smoothing");
  if (o.max_delay_s) limit += fmt::format(", delay ≤ {} ms", 1e3 * *o.max_delay_s);
  add_reasons(result, limit, o.vibration_tolerance, true);
  std::string mode_list;
  for (const KnownMode& m : modes)
    mode_list += fmt::format("{}{:.2f} Hz (ζ = {:.4f})", mode_list.empty() ? "" : ", ", m.freq_hz, m.zeta);
  result.reasons.push_back(fmt::format(
      "Designed with the fitted damping of {} mode{} {}; residual = worst over ±{:.0f} % frequency and ±{} damping. "
      "Designed for an assumed ζ = {} instead, {} would leave {}.",
      modes.size(), modes.size() > 1 ? "s" : "", mode_list, 100.0 * o.freq_uncertainty, o.zeta_uncertainty,
      o.assumed_zeta, result.recommended.name, percent(result.recommended.vibrations_assumed_damping)));
  for (const std::string& s : skipped) result.reasons.push_back("Not considered: " + s + ".");
  return result;
}

}  // namespace servotwin::shaping
