// Periodic (multisine) estimator: per-period DFTs, their mean and period-to-period scatter,
// excited-line detection, FRF with its variance (Pintelon & Schoukens 2012, section 2.4).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "offline_fft.hpp"
#include "offline_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/frf/excitation_recording.hpp"
#include "servotwin/frf/offline.hpp"

namespace servotwin::frf {

namespace {

std::string str(std::size_t v) { return std::to_string(v); }

std::string str(double v, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
  return buffer;
}

/// Running mean and (co)variance of the per-period spectra, per line (Welford's update, which
/// keeps full precision when the scatter is tiny next to the mean).
struct LineStatistics {
  explicit LineStatistics(std::size_t lines) : mean_x(lines), mean_y(lines), m2_x(lines), m2_y(lines), c_yx(lines) {}

  void add(const std::vector<std::complex<double>>& fx, const std::vector<std::complex<double>>& fy) {
    ++count;
    const double w = 1.0 / static_cast<double>(count);
    for (std::size_t k = 0; k < mean_x.size(); ++k) {
      const std::complex<double> dx = fx[k] - mean_x[k], dy = fy[k] - mean_y[k];
      mean_x[k] += w * dx;
      mean_y[k] += w * dy;
      const std::complex<double> dx_new = fx[k] - mean_x[k];
      m2_x[k] += std::real(dx * std::conj(dx_new));
      m2_y[k] += std::real(dy * std::conj(fy[k] - mean_y[k]));
      c_yx[k] += dy * std::conj(dx_new);
    }
  }

  std::size_t count = 0;
  std::vector<std::complex<double>> mean_x, mean_y;
  std::vector<double> m2_x, m2_y;
  std::vector<std::complex<double>> c_yx;
};

struct Layout {
  std::size_t period = 0, total_periods = 0, skipped = 0, used = 0, dropped = 0;
};

Layout resolve_layout(std::size_t n, const MultisineOptions& o) {
  Layout l;
  if (o.period_samples == 0 && o.periods == 0)
    throw core::InputError(core::at_field("periods"),
                           "give the number of periods in the record (--periods) or the period length in samples");
  l.period = o.period_samples != 0 ? o.period_samples : n / o.periods;
  if (l.period < 4)
    throw core::InputError(core::at_field(o.period_samples != 0 ? "period" : "periods"),
                           "a period of " + str(l.period) + " samples is too short (at least 4)");
  l.total_periods = o.periods != 0 ? o.periods : n / l.period;
  if (l.total_periods * l.period > n)
    throw core::InputError(core::at_field("periods"),
                           str(l.total_periods) + " periods of " + str(l.period) + " samples need " +
                               str(l.total_periods * l.period) + " samples, the record has " + str(n));
  l.skipped = o.skip_periods;
  if (l.skipped + 2 > l.total_periods)
    throw core::InputError(core::at_field("skip-periods"),
                           str(l.total_periods) + " periods minus " + str(l.skipped) +
                               " skipped leaves fewer than the 2 periods needed to estimate the noise");
  l.used = l.total_periods - l.skipped;
  l.dropped = n - l.total_periods * l.period;
  return l;
}

/// Below this correlation of consecutive periods the input does not repeat with the period the
/// layout assumes (detect_period's own threshold for a periodic recording).
constexpr double kMinPeriodCorrelation = 0.8;

/// Correlation coefficient of the used input with itself one period later: close to 1 when the
/// period is right (or a multiple of the true one), near 0 when not.
double period_correlation(std::span<const double> v, std::size_t period) {
  const std::size_t m = v.size() - period;
  double mean = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const double a = v[i] - mean, b = v[i + period] - mean;
    sab += a * b;
    saa += a * a;
    sbb += b * b;
  }
  return saa > 0.0 && sbb > 0.0 ? sab / std::sqrt(saa * sbb) : 1.0;
}

/// Issue 27 §3: `--periods 7` on a record of 8 periods cut it into pieces that do not repeat, and
/// the estimator returned a handful of meaningless lines without a word. Refuse, saying where the
/// input does repeat.
void require_periodic_input(std::span<const double> x, const Layout& l, const MultisineOptions& o) {
  const auto used = x.subspan(l.skipped * l.period, l.used * l.period);
  const double c = period_correlation(used, l.period);
  if (c >= kMinPeriodCorrelation) return;
  const PeriodDetection found = detect_period(x);
  std::string hint;
  if (found.period_samples != 0) {
    hint = "; it repeats every " + str(found.period_samples) + " samples (correlation " + str(found.correlation, 3) + ")";
    if (x.size() % found.period_samples == 0) hint += ", " + str(x.size() / found.period_samples) + " periods in the record";
  }
  throw core::InputError(core::at_field(o.period_samples != 0 ? "period" : "periods"),
                         "the input does not repeat every " + str(l.period) + " samples (" + str(l.total_periods) +
                             " periods): consecutive periods correlate " + str(c, 3) + ", below " +
                             str(kMinPeriodCorrelation, 1) + hint);
}

/// Slope per sample of the drift line through the period means (see MultisineOptions::detrend).
double drift_slope(std::span<const double> v, std::size_t period, std::size_t periods) {
  const double center = 0.5 * static_cast<double>(periods - 1);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t p = 0; p < periods; ++p) {
    double mean = 0.0;
    for (std::size_t i = 0; i < period; ++i) mean += v[p * period + i];
    mean /= static_cast<double>(period);
    const double d = static_cast<double>(p) - center;
    sxy += d * mean;
    sxx += d * d;
  }
  return sxy / sxx / static_cast<double>(period);
}

double mean_of(std::span<const double> v) {
  double sum = 0.0;
  for (double s : v) sum += s;
  return sum / static_cast<double>(v.size());
}

/// Copies period p of `v` into `out`, minus the drift line (or mean).
void load_period(std::span<const double> v, std::size_t p, std::size_t period, double offset, double slope,
                 double center, std::vector<double>& out) {
  for (std::size_t i = 0; i < period; ++i) {
    const std::size_t at = p * period + i;
    out[i] = v[at] - offset - slope * (static_cast<double>(at) - center);
  }
}

std::vector<std::size_t> explicit_lines(const MultisineOptions& o, std::size_t last_line) {
  std::vector<std::size_t> lines = o.excited_lines;
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  for (std::size_t k : lines)
    if (k == 0 || k > last_line)
      throw core::InputError(core::at_field("excited_lines"),
                             "line " + str(k) + " is outside 1 … " + str(last_line) + " (period / 2)");
  return lines;
}

/// Lines whose input power passes the threshold, or the largest-gap rule (see MultisineOptions).
std::vector<std::size_t> detect_lines(const LineStatistics& stats, const MultisineOptions& o) {
  constexpr double kFloorDb = -60.0;
  // Automatic detection first keeps only lines whose mean stands 20 dB above its own
  // period-to-period scatter (|X̄|² > 100·σ²_X/P): a line of broadband noise passes with
  // probability (1 + 100/(P−1))^−(P−1) (F distribution), < 1 % for any P >= 2.
  constexpr double kMinInputSnr = 100.0;
  const std::vector<std::complex<double>>& mean_x = stats.mean_x;
  const double periods = static_cast<double>(stats.count);
  constexpr double kMinGapDb = 6.0;
  const std::size_t last = mean_x.size() - 1;
  double peak = 0.0;
  for (std::size_t k = 1; k <= last; ++k) peak = std::max(peak, std::norm(mean_x[k]));
  if (!(peak > 0.0))
    throw core::InputError(core::at_field("input"), "the input has no power on any line above DC: it is not a multisine");
  std::vector<double> db(last + 1, kFloorDb);
  for (std::size_t k = 1; k <= last; ++k) {
    const double p = std::norm(mean_x[k]);
    const double scatter = stats.m2_x[k] / (periods - 1.0) / periods;
    const bool stands_out = o.excitation_threshold_db || p > kMinInputSnr * scatter;
    db[k] = p > 0.0 && stands_out ? std::max(kFloorDb, 10.0 * std::log10(p / peak)) : kFloorDb;
  }
  double threshold = 0.0;
  if (o.excitation_threshold_db) {
    threshold = *o.excitation_threshold_db;
    if (!(threshold <= 0.0))
      throw core::InputError(core::at_field("excitation-threshold-db"),
                             "the threshold is relative to the strongest line and must be <= 0 dB");
  } else {
    std::vector<double> sorted(db.begin() + 1, db.end());
    std::sort(sorted.begin(), sorted.end(), std::greater<>());
    double gap = 0.0;
    for (std::size_t i = 0; i + 1 < sorted.size(); ++i) {
      if (sorted[i] - sorted[i + 1] > gap) {
        gap = sorted[i] - sorted[i + 1];
        threshold = 0.5 * (sorted[i] + sorted[i + 1]);
      }
    }
    if (gap < kMinGapDb || sorted.front() <= kFloorDb)
      throw core::InputError(core::at_field("input"),
                             "cannot tell excited lines from the rest: the input's line powers show no gap of " +
                                 str(kMinGapDb, 0) + " dB or more (largest " + str(gap, 1) +
                                 " dB); check the period, give an excitation threshold, or use the H1 method for "
                                 "broadband signals");
  }
  std::vector<std::size_t> lines;
  for (std::size_t k = 1; k <= last; ++k)
    if (db[k] >= threshold) lines.push_back(k);
  return lines;
}

}  // namespace

MultisineEstimate estimate_multisine(std::span<const double> x, std::span<const double> y, double ts,
                                     const MultisineOptions& options) {
  detail::check_signals(x, y, ts);
  const Layout layout = resolve_layout(x.size(), options);
  require_periodic_input(x, layout, options);
  const std::size_t n_period = layout.period;
  const auto used_x = x.subspan(layout.skipped * n_period, layout.used * n_period);
  const auto used_y = y.subspan(layout.skipped * n_period, layout.used * n_period);

  double slope_x = 0.0, slope_y = 0.0;
  double offset_x = 0.0, offset_y = 0.0;
  const double center = 0.5 * static_cast<double>(used_x.size() - 1);
  if (options.detrend != Detrend::kNone) {
    offset_x = mean_of(used_x);
    offset_y = mean_of(used_y);
  }
  if (options.detrend == Detrend::kLinear) {
    slope_x = drift_slope(used_x, n_period, layout.used);
    slope_y = drift_slope(used_y, n_period, layout.used);
  }

  const std::size_t last_line = n_period / 2;
  LineStatistics stats(last_line + 1);
  detail::RealDft dft;
  std::vector<double> bx(n_period), by(n_period);
  std::vector<std::complex<double>> fx, fy;
  for (std::size_t p = 0; p < layout.used; ++p) {
    load_period(used_x, p, n_period, offset_x, slope_x, center, bx);
    load_period(used_y, p, n_period, offset_y, slope_y, center, by);
    dft.forward(bx, fx);
    dft.forward(by, fy);
    stats.add(fx, fy);
  }

  MultisineEstimate e;
  e.lines = options.excited_lines.empty() ? detect_lines(stats, options) : explicit_lines(options, last_line);
  e.period_samples = n_period;
  e.periods_used = layout.used;
  e.periods_skipped = layout.skipped;
  e.samples_dropped = layout.dropped;
  e.df_hz = 1.0 / (static_cast<double>(n_period) * ts);
  e.response.quality_kind = core::QualityKind::kCoherence;
  e.response.duration_s = static_cast<double>(x.size()) * ts;

  // Explicit lines more than 100 dB below the strongest one hold rounding noise, not excitation.
  constexpr double kNoPower = 1e-10;
  double peak = 0.0;
  for (std::size_t k = 1; k <= last_line; ++k) peak = std::max(peak, std::norm(stats.mean_x[k]));
  const double periods = static_cast<double>(layout.used);
  const double dof = periods - 1.0;
  for (std::size_t k : e.lines) {
    const std::complex<double> mx = stats.mean_x[k], my = stats.mean_y[k];
    const double px = std::norm(mx);
    if (!(px > kNoPower * peak))
      throw core::InputError(core::at_field("excited_lines"),
                             "line " + str(k) + " has no input power (more than 100 dB below the strongest line)");
    const double var_x = stats.m2_x[k] / dof, var_y = stats.m2_y[k] / dof;
    const std::complex<double> cov_yx = stats.c_yx[k] / dof;
    core::FrequencyPoint point;
    point.freq_hz = static_cast<double>(k) * e.df_hz;
    point.value = my / mx;
    // σ²_G = var(Ȳ − G·X̄)/|X̄|², the section 2.4 expression multiplied out so that it needs no
    // division by Ȳ.
    const double g2 = std::norm(point.value);
    const double var_g =
        std::max(0.0, (var_y + g2 * var_x - 2.0 * std::real(cov_yx * std::conj(point.value))) / (periods * px));
    point.std_dev = std::sqrt(var_g);
    point.snr = point.std_dev > 0.0 ? std::sqrt(g2) / point.std_dev : 0.0;
    const double denominator = g2 + periods * var_g;
    point.quality = denominator > 0.0 ? g2 / denominator : 0.0;
    const bool nyquist = n_period % 2 == 0 && k == last_line;
    point.amplitude = (nyquist ? 1.0 : 2.0) * std::sqrt(px) / static_cast<double>(n_period);
    e.response.points.push_back(point);
    e.noise_var_x.push_back(var_x);
    e.noise_var_y.push_back(var_y);
    e.noise_cov_yx.push_back(cov_yx);
  }
  return e;
}

}  // namespace servotwin::frf
