#include "servotwin/report/shaper_report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <utility>

#include "servotwin/core/error.hpp"
#include "servotwin/shaping/smoothing.hpp"
#include "number_format.hpp"

namespace servotwin::report {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr std::size_t kMaxCurvePoints = 100000;
constexpr std::size_t kDampingPoints = 401;
/// Default frequency axis: up to this multiple of the highest design frequency (past the second
/// design-frequency lobe of the longer shapers, where their robustness differs most).
constexpr double kDefaultFreqSpan = 2.5;

std::string num(double v, int digits = 4) { return detail::format_number(v, digits); }

std::string shaper_where(std::size_t i) { return "shapers[" + std::to_string(i) + "]"; }

void check_shapers(const std::vector<NamedShaper>& shapers) {
  if (shapers.empty()) throw core::InputError(core::at_field("shapers"), "expected at least one shaper to compare");
  for (std::size_t i = 0; i < shapers.size(); ++i) {
    const shaping::Shaper& s = shapers[i].shaper;
    if (s.times.empty() || s.times.size() != s.amplitudes.size())
      throw core::InputError(core::at_field(shaper_where(i)),
                             fmt::format("shaper '{}' has {} impulse times and {} amplitudes; expected the same "
                                         "number, at least one",
                                         shapers[i].name, s.times.size(), s.amplitudes.size()));
    if (!std::isfinite(s.omega) || s.omega <= 0.0)
      throw core::InputError(core::at_field(shaper_where(i)),
                             fmt::format("shaper '{}' has design frequency {} rad/s; expected a finite value > 0",
                                         shapers[i].name, s.omega));
  }
}

void check_options(const ShaperReportOptions& o) {
  if (!std::isfinite(o.max_smoothing) || o.max_smoothing <= 0.0)
    throw core::InputError(core::at_field("max_smoothing"),
                           fmt::format("expected a smoothing limit > 0, got {}", o.max_smoothing));
}

/// The even `grid` with the `exact` points added: sorted, and a grid point closer than `tolerance`
/// to another point left out (the chart aligns series on their x values, and two x printing alike
/// would collapse into one). Exact points are kept as given, so a design frequency is a point.
std::vector<double> with_exact_points(const std::vector<double>& grid, std::vector<double> exact, double tolerance) {
  std::sort(exact.begin(), exact.end());
  exact.erase(std::unique(exact.begin(), exact.end(), [&](double a, double b) { return b - a <= tolerance; }), exact.end());
  std::vector<double> out = exact;
  for (double x : grid) {
    const auto next = std::lower_bound(exact.begin(), exact.end(), x);
    const bool near_next = next != exact.end() && *next - x <= tolerance;
    const bool near_previous = next != exact.begin() && x - *std::prev(next) <= tolerance;
    if (!near_next && !near_previous) out.push_back(x);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<double> even_grid(double low, double high, std::size_t count) {
  std::vector<double> g(count);
  for (std::size_t k = 0; k < count; ++k)
    g[k] = low + (high - low) * static_cast<double>(k) / static_cast<double>(count - 1);
  return g;
}

std::string label(const NamedShaper& s) { return s.name + " (" + s.shaper.type + ")"; }

Section comparison_section(const std::vector<ShaperComparison>& rows, const ShaperReportOptions& o) {
  const shaping::ComparisonOptions& c = o.comparison;
  Section s;
  s.title = "Comparison";
  s.text = fmt::format(
      "Every shaper is evaluated at its own design frequency and damping. Residual vibration V is the vibration left "
      "after the last impulse relative to an unshaped move (0 % = cancelled, 100 % = no reduction). The insensitivity "
      "band is the frequency interval around the design frequency where V stays at or below {:g} %; its width is given "
      "relative to the design frequency. Duration is the delay the shaper adds to every move.\n\n"
      "Smoothing is Klipper's measure: the distance of the shaped path from the programmed one at a 90° corner and a "
      "180° reversal, at acceleration {:g} and square-corner velocity {:g} (Klipper's units: mm/s², mm/s, mm). The "
      "suggested maximum acceleration keeps smoothing at or below {:g} at that square-corner velocity "
      "(Klipper's max_accel).",
      100.0 * c.level, c.accel, c.scv, o.max_smoothing);
  Table t;
  t.title = "Shapers";
  t.header = {"shaper",
              "type",
              "design f [Hz]",
              "design zeta",
              "impulses",
              "duration [s]",
              "V at design [%]",
              fmt::format("band V <= {:g} % [Hz]", 100.0 * c.level),
              "band width / f",
              "smoothing",
              fmt::format("max accel (smoothing <= {:g})", o.max_smoothing)};
  for (const ShaperComparison& r : rows) {
    const bool band = r.row.band_width_normalized > 0.0;
    t.rows.push_back({r.name, r.row.type, num(r.freq_hz, 6), num(r.zeta, 4), std::to_string(r.row.impulse_count),
                      num(r.row.duration_s, 5), num(100.0 * r.row.residual_at_design, 3),
                      band ? fmt::format("{} to {}", num(r.row.band_low_ratio * r.freq_hz), num(r.row.band_high_ratio * r.freq_hz))
                           : "empty",
                      num(r.row.band_width_normalized, 3), num(r.row.smoothing, 4),
                      std::isinf(r.max_accel) ? "unlimited" : (std::isnan(r.max_accel) ? "none" : num(r.max_accel, 5))});
  }
  s.tables.push_back(std::move(t));
  return s;
}

Section frequency_section(const std::vector<NamedShaper>& shapers, const std::vector<ShaperComparison>& rows,
                          const ShaperReportOptions& o) {
  double f_top = 0.0;
  for (const ShaperComparison& r : rows) f_top = std::max(f_top, r.freq_hz);
  const double f_min = o.freq_min_hz.value_or(0.0);
  const double f_max = o.freq_max_hz.value_or(kDefaultFreqSpan * f_top);
  if (!std::isfinite(f_min) || f_min < 0.0)
    throw core::InputError(core::at_field("freq_min_hz"), fmt::format("expected a frequency >= 0 Hz, got {}", f_min));
  if (!std::isfinite(f_max) || f_max <= f_min)
    throw core::InputError(core::at_field("freq_max_hz"),
                           fmt::format("expected a frequency above the lower end {} Hz, got {}", f_min, f_max));

  // The even grid plus each design frequency and band edge inside the range: the notches and the
  // level crossings then lie on the curves exactly.
  std::vector<double> exact;
  const auto add_inside = [&](double extra) {
    if (extra > f_min && extra < f_max) exact.push_back(extra);
  };
  for (const ShaperComparison& r : rows) {
    add_inside(r.freq_hz);
    if (r.row.band_width_normalized > 0.0) {
      add_inside(r.row.band_low_ratio * r.freq_hz);
      add_inside(r.row.band_high_ratio * r.freq_hz);
    }
  }
  const std::vector<double> f = with_exact_points(even_grid(f_min, f_max, o.curve_points), std::move(exact), 1e-7 * (f_max - f_min));

  Chart chart;
  chart.title = "Residual vibration versus mode frequency (each shaper at its design damping)";
  chart.x_label = "mode frequency [Hz]";
  chart.y_label = "residual vibration V [%]";
  for (const NamedShaper& s : shapers) {
    Series series{label(s), f, std::vector<double>(f.size())};
    for (std::size_t k = 0; k < f.size(); ++k)
      series.y[k] = 100.0 * shaping::residual_vibration(s.shaper, kTwoPi * f[k], s.shaper.zeta);
    chart.series.push_back(std::move(series));
  }
  const double level = 100.0 * o.comparison.level;
  chart.series.push_back({fmt::format("level {:g} %", level), {f.front(), f.back()}, {level, level}});

  Section s;
  s.title = "Sensitivity to frequency";
  s.text = fmt::format(
      "How much vibration each shaper leaves when the mode is not at its design frequency, from {:g} to {:g} Hz. "
      "Where a curve stays below the {:g} % line is its insensitivity band.",
      f_min, f_max, level);
  s.charts.push_back(std::move(chart));
  return s;
}

Section damping_section(const std::vector<NamedShaper>& shapers) {
  double zeta_top = 0.0;
  for (const NamedShaper& s : shapers) zeta_top = std::max(zeta_top, s.shaper.zeta);
  const double zeta_max = std::min(0.9, std::max(0.25, 2.0 * zeta_top));
  std::vector<double> design;
  for (const NamedShaper& s : shapers) design.push_back(s.shaper.zeta);
  const std::vector<double> zetas = with_exact_points(even_grid(0.0, zeta_max, kDampingPoints), std::move(design), 1e-7 * zeta_max);

  Chart chart;
  chart.title = "Residual vibration at the design frequency versus mode damping";
  chart.x_label = "mode damping ratio zeta";
  chart.y_label = "residual vibration V [%]";
  for (const NamedShaper& s : shapers) {
    Series series{label(s), zetas, shaping::damping_sensitivity(s.shaper, zetas)};
    for (double& v : series.y) v *= 100.0;
    chart.series.push_back(std::move(series));
  }
  Section s;
  s.title = "Sensitivity to damping";
  s.text = fmt::format(
      "Vibration left at each shaper's design frequency when the mode's damping differs from the damping the shaper "
      "was designed for (the design damping is in the table), for damping 0 to {:g}.",
      zeta_max);
  s.charts.push_back(std::move(chart));
  return s;
}

/// The time span the impulse and step charts show: the longest shaper, or half a period of the
/// highest design frequency when every shaper is a single impulse.
double time_horizon(const std::vector<NamedShaper>& shapers) {
  double longest = 0.0, omega_top = 0.0;
  for (const NamedShaper& s : shapers) {
    longest = std::max(longest, s.shaper.duration());
    omega_top = std::max(omega_top, s.shaper.omega);
  }
  return longest > 0.0 ? longest : std::numbers::pi / omega_top;
}

double min_spacing(const shaping::Shaper& s) {
  double spacing = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < s.times.size(); ++i) spacing = std::min(spacing, s.times[i] - s.times[i - 1]);
  return spacing;
}

Section impulse_section(const std::vector<NamedShaper>& shapers, double horizon) {
  Chart chart;
  chart.title = "Impulse trains (each impulse a narrow spike from 0 to its amplitude)";
  chart.x_label = "time [s]";
  chart.y_label = "amplitude A_i";
  for (const NamedShaper& s : shapers) {
    // A line chart draws one value per x, so a stem becomes a spike (t - w, 0), (t, A), (t + w, 0)
    // too narrow to see as anything but a line, and narrower than a quarter of the impulse spacing.
    const double w = std::min(3e-3 * horizon, 0.25 * min_spacing(s.shaper));
    Series series{label(s), {}, {}};
    for (std::size_t i = 0; i < s.shaper.times.size(); ++i) {
      const double t = s.shaper.times[i];
      series.x.insert(series.x.end(), {t - w, t, t + w});
      series.y.insert(series.y.end(), {0.0, s.shaper.amplitudes[i], 0.0});
    }
    chart.series.push_back(std::move(series));
  }
  Section s;
  s.title = "Impulses";
  s.text = "Times and amplitudes of the impulses of every shaper (hover for the values at the tips).";
  s.charts.push_back(std::move(chart));
  return s;
}

Section step_section(const std::vector<NamedShaper>& shapers, double horizon) {
  const double t_begin = -0.1 * horizon, t_end = 1.2 * horizon;
  Chart chart;
  chart.title = "Shaped unit step: the command after the shaper";
  chart.x_label = "time [s]";
  chart.y_label = "shaped command";
  // A staircase: the value before an impulse ends just before its time, so each step is drawn
  // (nearly) vertical; `rise` stays far below the impulse spacing.
  const double unshaped_rise = 1e-4 * horizon;
  chart.series.push_back({"unshaped step", {t_begin, -unshaped_rise, 0.0, t_end}, {0.0, 0.0, 1.0, 1.0}});
  for (const NamedShaper& s : shapers) {
    const double rise = std::min(unshaped_rise, 1e-2 * min_spacing(s.shaper));
    Series series{label(s), {t_begin}, {0.0}};
    double sum = 0.0;
    for (std::size_t i = 0; i < s.shaper.times.size(); ++i) {
      const double t = s.shaper.times[i];
      series.x.insert(series.x.end(), {t - rise, t});
      series.y.push_back(sum);
      sum += s.shaper.amplitudes[i];
      series.y.push_back(sum);
    }
    series.x.push_back(t_end);
    series.y.push_back(sum);
    chart.series.push_back(std::move(series));
  }
  Section s;
  s.title = "Step response";
  s.text = "A unit step command convolved with each shaper: the command reaches its end value at the shaper's "
           "duration, which is the delay the shaper adds to every move.";
  s.charts.push_back(std::move(chart));
  return s;
}

}  // namespace

std::vector<ShaperComparison> shaper_comparison(const std::vector<NamedShaper>& shapers,
                                                const ShaperReportOptions& options) {
  check_shapers(shapers);
  check_options(options);
  std::vector<shaping::Shaper> plain;
  plain.reserve(shapers.size());
  for (const NamedShaper& s : shapers) plain.push_back(s.shaper);
  const std::vector<shaping::ShaperComparisonRow> rows = shaping::compare_shapers(plain, options.comparison);
  std::vector<ShaperComparison> out;
  out.reserve(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    ShaperComparison c;
    c.name = shapers[i].name;
    c.row = rows[i];
    c.freq_hz = shapers[i].shaper.omega / kTwoPi;
    c.zeta = shapers[i].shaper.zeta;
    c.max_accel = shaping::reachable_max_accel(shapers[i].shaper, options.max_smoothing, options.comparison.scv)
                      .value_or(std::numeric_limits<double>::quiet_NaN());
    out.push_back(std::move(c));
  }
  return out;
}

Document shaper_report(const std::vector<NamedShaper>& shapers, const ShaperReportOptions& options) {
  if (options.curve_points < 2 || options.curve_points > kMaxCurvePoints)
    throw core::InputError(core::at_field("curve_points"),
                           fmt::format("expected 2 to {} points per curve, got {}", kMaxCurvePoints, options.curve_points));
  const std::vector<ShaperComparison> rows = shaper_comparison(shapers, options);
  Document doc;
  doc.title = options.title;
  std::string names;
  for (const NamedShaper& s : shapers) names += (names.empty() ? "" : ", ") + s.name;
  doc.subtitle = fmt::format("{} shaper{}: {}", shapers.size(), shapers.size() == 1 ? "" : "s", names);
  doc.sections.push_back(comparison_section(rows, options));
  doc.sections.push_back(frequency_section(shapers, rows, options));
  doc.sections.push_back(damping_section(shapers));
  const double horizon = time_horizon(shapers);
  doc.sections.push_back(impulse_section(shapers, horizon));
  doc.sections.push_back(step_section(shapers, horizon));
  return doc;
}

}  // namespace servotwin::report
