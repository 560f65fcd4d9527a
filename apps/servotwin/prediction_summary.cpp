#include "prediction_summary.hpp"

#include <cmath>
#include <fmt/core.h>

namespace servotwin::cli {

namespace {

constexpr double kUm = 1000.0;  ///< µm per mm (the program's unit)

struct Extent {
  double sum2 = 0.0, max = 0.0;
  std::size_t n = 0;
  void add(double v) {
    sum2 += v * v;
    max = std::max(max, std::abs(v));
    ++n;
  }
  [[nodiscard]] double rms() const { return n == 0 ? 0.0 : std::sqrt(sum2 / static_cast<double>(n)); }
};

}  // namespace

void print_prediction_summary(const vcnc::Prediction& p) {
  for (const auto& w : p.warnings) fmt::print(stderr, "warning: {}\n", w);
  for (const auto& n : p.notes) fmt::print("note: {}\n", n);
  // Errors in µm, as in the report (issue 27 §4: the summary printed mm beside a report in µm).
  fmt::print("prediction: {} samples ({:.3f} s at ts = {} s), errors in µm\n", p.size(),
             static_cast<double>(p.size() > 0 ? p.size() - 1 : 0) * p.ts, p.ts);
  for (std::size_t i = 0; i < p.axes.size(); ++i) {
    Extent e;
    for (std::size_t k = 0; k < p.size(); ++k) e.add(p.tracking_error(i, k));
    fmt::print("  axis {} tracking error: rms {:.4g} µm, max {:.4g} µm\n", motion::axis_name(p.axes[i]), kUm * e.rms(),
               kUm * e.max);
  }
  Extent all;
  std::array<Extent, motion::kPathKindCount> by_kind{};
  for (std::size_t k = 0; k < p.size(); ++k) {
    all.add(p.contour_error[k]);
    by_kind[static_cast<std::size_t>(p.kind[k])].add(p.contour_error[k]);
  }
  fmt::print("  contour error: rms {:.4g} µm, max {:.4g} µm", kUm * all.rms(), kUm * all.max);
  for (std::size_t k = 0; k < by_kind.size(); ++k) {
    if (by_kind[k].n == 0) continue;
    fmt::print("; {} rms {:.4g} max {:.4g}", motion::path_kind_name(static_cast<motion::PathKind>(k)), kUm * by_kind[k].rms(),
               kUm * by_kind[k].max);
  }
  fmt::print("\n");
}

void print_comparison(const vcnc::MeasuredComparison& m, double ts, bool from_trace) {
  if (from_trace) {
    fmt::print("measured: the trace's own positions, {} samples compared (errors in µm)\n", m.count);
  } else {
    fmt::print("measured capture aligned at offset {} samples ({:+.3f} s); {} samples compared (errors in µm); command "
               "mismatch rms {:.3g} µm\n",
               m.offset, static_cast<double>(m.offset) * ts, m.count, kUm * m.command_mismatch_rms);
  }
  fmt::print("  {:<12} {:<6} {:>12} {:>12} {:>12} {:>8}\n", "quantity", "path", "measured rms", "predicted rms",
             "max |diff|", "nrmse");
  for (const auto& s : m.scores) {
    fmt::print("  {:<12} {:<6} {:>12.4g} {:>12.4g} {:>12.4g} {:>8.4f}\n", s.quantity, s.kind, kUm * s.metrics.rms_measured,
               kUm * s.metrics.rms_predicted, kUm * s.metrics.max_difference, s.metrics.nrmse);
  }
}

}  // namespace servotwin::cli
