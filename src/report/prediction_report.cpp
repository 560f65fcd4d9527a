// The prediction report (prediction_report.hpp): tracking and contour errors of a program as
// predicted by axis models, beside a measurement when there is one.
#include "servotwin/report/prediction_report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace servotwin::report {

namespace {

std::string um(double mm) { return std::isfinite(mm) ? fmt::format("{:.3f}", 1000.0 * mm) : "-"; }

std::vector<double> times(const vcnc::Prediction& p) {
  std::vector<double> t(p.size());
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = static_cast<double>(k) * p.ts;
  return t;
}

/// Distance travelled by the commanded point along its path, per sample.
std::vector<double> travelled(const vcnc::Prediction& p) {
  std::vector<double> s(p.size(), 0.0);
  for (std::size_t k = 1; k < s.size(); ++k) {
    double d2 = 0.0;
    for (const auto& c : p.command) d2 += (c[k] - c[k - 1]) * (c[k] - c[k - 1]);
    s[k] = s[k - 1] + std::sqrt(d2);
  }
  return s;
}

std::vector<double> in_um(const std::vector<double>& mm) {
  std::vector<double> out(mm.size());
  for (std::size_t k = 0; k < mm.size(); ++k) out[k] = 1000.0 * mm[k];
  return out;
}

struct Extent {
  double sum2 = 0.0, max = 0.0;
  std::size_t n = 0;
  void add(double v) {
    if (!std::isfinite(v)) return;
    sum2 += v * v;
    max = std::max(max, std::abs(v));
    ++n;
  }
  [[nodiscard]] double rms() const { return n == 0 ? std::nan("") : std::sqrt(sum2 / static_cast<double>(n)); }
};

Section summary_section(const std::string& name, const vcnc::Prediction& p, const vcnc::MeasuredComparison* m) {
  Section s;
  s.title = name + ": summary";
  s.text = fmt::format("{} samples at ts = {} s ({:.3f} s). Tracking error = command - position; contour error = distance "
                       "from the point to the commanded path, positive to the left of the direction of travel. Errors in um.",
                       p.size(), p.ts, static_cast<double>(p.size() > 0 ? p.size() - 1 : 0) * p.ts);
  for (const std::string& w : p.warnings) s.text += "\n\nWarning: " + w;
  Table predicted;
  predicted.title = "Predicted errors";
  predicted.header = {"quantity", "path", "rms [um]", "max [um]"};
  for (std::size_t i = 0; i < p.axes.size(); ++i) {
    Extent e;
    for (std::size_t k = 0; k < p.size(); ++k) e.add(p.tracking_error(i, k));
    predicted.rows.push_back({std::string(motion::axis_name(p.axes[i])) + " tracking", "all", um(e.rms()), um(e.max)});
  }
  Extent all;
  std::array<Extent, motion::kPathKindCount> by_kind{};
  for (std::size_t k = 0; k < p.size(); ++k) {
    all.add(p.contour_error[k]);
    by_kind[static_cast<std::size_t>(p.kind[k])].add(p.contour_error[k]);
  }
  predicted.rows.push_back({"contour", "all", um(all.rms()), um(all.max)});
  for (std::size_t k = 0; k < by_kind.size(); ++k) {
    if (by_kind[k].n == 0) continue;
    predicted.rows.push_back(
        {"contour", motion::path_kind_name(static_cast<motion::PathKind>(k)), um(by_kind[k].rms()), um(by_kind[k].max)});
  }
  s.tables.push_back(std::move(predicted));
  if (m != nullptr) {
    s.text += fmt::format("\n\nMeasured capture aligned at offset {} samples; {} samples compared; commanded positions "
                          "differ by {:.3g} RMS after alignment.",
                          m->offset, m->count, m->command_mismatch_rms);
    Table scores;
    scores.title = "Predicted vs measured";
    scores.header = {"quantity", "path", "measured rms [um]", "predicted rms [um]", "rms difference [um]", "max |difference| [um]",
                     "nrmse"};
    for (const auto& sc : m->scores) {
      scores.rows.push_back({sc.quantity, sc.kind, um(sc.metrics.rms_measured), um(sc.metrics.rms_predicted),
                             um(sc.metrics.rms_difference), um(sc.metrics.max_difference), fmt::format("{:.4f}", sc.metrics.nrmse)});
    }
    s.tables.push_back(std::move(scores));
  }
  return s;
}

/// A time or distance chart of the measured (when there is a measurement) and predicted values.
Chart measured_and_predicted(std::string title, std::string x_label, std::string y_label, const std::vector<double>& x,
                             const std::vector<double>* measured, std::vector<double> predicted) {
  Chart c;
  c.title = std::move(title);
  c.x_label = std::move(x_label);
  c.y_label = std::move(y_label);
  if (measured != nullptr) c.series.push_back({"measured", x, *measured});
  c.series.push_back({"predicted", x, std::move(predicted)});
  return c;
}

Section tracking_section(const std::string& name, const vcnc::Prediction& p, const vcnc::MeasuredComparison* m,
                         const std::vector<double>& t) {
  Section s;
  s.title = name + ": tracking errors";
  for (std::size_t i = 0; i < p.axes.size(); ++i) {
    std::vector<double> e(p.size());
    for (std::size_t k = 0; k < p.size(); ++k) e[k] = 1000.0 * p.tracking_error(i, k);
    const std::vector<double> measured = m != nullptr ? in_um(m->tracking_error[i]) : std::vector<double>{};
    s.charts.push_back(measured_and_predicted(fmt::format("Axis {} tracking error", motion::axis_name(p.axes[i])),
                                              "time [s]", "tracking error [um]", t, m != nullptr ? &measured : nullptr,
                                              std::move(e)));
  }
  return s;
}

Section contour_section(const std::string& name, const vcnc::Prediction& p, const vcnc::MeasuredComparison* m,
                        const std::vector<double>& t) {
  Section s;
  s.title = name + ": contour error";
  const std::vector<double> measured = m != nullptr ? in_um(m->contour_error) : std::vector<double>{};
  const std::vector<double>* measured_or_null = m != nullptr ? &measured : nullptr;
  Chart path = measured_and_predicted("Contour error along the path", "distance travelled by the command [mm]",
                                      "contour error [um]", travelled(p), measured_or_null, in_um(p.contour_error));
  // The distance stands still during stops: keep x increasing for the line chart by dropping
  // repeated positions (their errors are drawn in the time chart below).
  for (auto& series : path.series) {
    Series kept{series.label, {}, {}};
    for (std::size_t k = 0; k < series.x.size(); ++k) {
      if (k > 0 && !(series.x[k] > kept.x.back())) continue;
      kept.x.push_back(series.x[k]);
      kept.y.push_back(series.y[k]);
    }
    series = std::move(kept);
  }
  s.charts.push_back(std::move(path));
  s.charts.push_back(measured_and_predicted("Contour error over time", "time [s]", "contour error [um]", t,
                                            measured_or_null, in_um(p.contour_error)));
  return s;
}

/// 1, 2, 5, 10, 20, ... : the largest such factor that shows the largest deviation at no more than
/// `target` (at least 1).
double magnification(double largest_deviation, double target) {
  if (!(largest_deviation > 0.0)) return 1.0;
  const double raw = target / largest_deviation;
  if (raw <= 1.0) return 1.0;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double step : {5.0, 2.0, 1.0})
    if (step * decade <= raw) return step * decade;
  return decade;
}

Section path_section(const std::string& name, const vcnc::Prediction& p, const vcnc::MeasuredComparison* m) {
  Section s;
  s.title = name + ": path";
  if (p.axes.size() < 2) {
    s.text = "One axis only: no path in a plane to draw.";
    return s;
  }
  const std::size_t a = static_cast<std::size_t>(p.axes[0]), b = static_cast<std::size_t>(p.axes[1]);
  double extent = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto [lo, hi] = std::minmax_element(p.command[i].begin(), p.command[i].end());
    extent = std::max(extent, *hi - *lo);
  }
  for (double e : p.contour_error) largest = std::max(largest, std::abs(e));
  if (m != nullptr)
    for (double e : m->contour_error)
      if (std::isfinite(e)) largest = std::max(largest, std::abs(e));
  const double factor = magnification(largest, 0.1 * extent);

  // Each point moved away from its nearest path point by `factor` times its deviation.
  auto magnified = [&](const std::vector<std::vector<double>>& actual, const char* label) {
    Series out{label, {}, {}};
    out.x.resize(p.size());
    out.y.resize(p.size());
    motion::Point q = p.path->start_point();
    for (std::size_t k = 0; k < p.size(); ++k) {
      for (std::size_t i = 0; i < p.axes.size(); ++i) q[static_cast<std::size_t>(p.axes[i])] = actual[i][k];
      if (!std::isfinite(q[a]) || !std::isfinite(q[b])) {
        out.x[k] = out.y[k] = std::nan("");
        continue;
      }
      const motion::ContourPoint c = p.path->nearest(k, q);
      out.x[k] = c.nearest[a] + factor * (q[a] - c.nearest[a]);
      out.y[k] = c.nearest[b] + factor * (q[b] - c.nearest[b]);
    }
    return out;
  };
  Chart c;
  c.title = fmt::format("Path in {}{}, deviation magnified {:g}x", motion::axis_letter(p.axes[0]),
                        motion::axis_letter(p.axes[1]), factor);
  c.x_label = fmt::format("{} [mm]", motion::axis_name(p.axes[0]));
  c.y_label = fmt::format("{} [mm]", motion::axis_name(p.axes[1]));
  c.equal_axes = true;
  c.series.push_back({"command", p.command[0], p.command[1]});
  if (m != nullptr) c.series.push_back(magnified(m->actual, "measured"));
  c.series.push_back(magnified(p.predicted, "predicted"));
  s.charts.push_back(std::move(c));
  return s;
}

}  // namespace

std::vector<Section> prediction_sections(const std::string& name, const vcnc::Prediction& prediction,
                                         const vcnc::MeasuredComparison* measured) {
  const std::vector<double> t = times(prediction);
  return {summary_section(name, prediction, measured), tracking_section(name, prediction, measured, t),
          contour_section(name, prediction, measured, t), path_section(name, prediction, measured)};
}

Document prediction_report(const std::string& program_name, const vcnc::Prediction& prediction,
                           const vcnc::MeasuredComparison* measured) {
  Document doc;
  doc.title = "Prediction: " + program_name;
  doc.subtitle = measured != nullptr ? "predicted by the identified axis models, compared with a measured capture"
                                     : "predicted by the identified axis models";
  doc.sections = prediction_sections(program_name, prediction, measured);
  return doc;
}

}  // namespace servotwin::report
