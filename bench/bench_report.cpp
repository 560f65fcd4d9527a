// HTML reports: writing the report of a 10-minute, 3-axis, 1 kHz prediction (600 000 samples per
// series; per axis commanded and predicted position and tracking error, the contour error, and
// the XY path commanded and with the error magnified), and the display decimation it rests on.
//
// Targets (Release, one core): write_html of that document <= 200 ms and <= 5 MB (the issue's
// size limit; counter "bytes"); display_indices >= 100 M samples/s; display_path_indices of a
// 600 000-point path <= 30 ms.

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "servotwin/report/document.hpp"

namespace {

using namespace servotwin;

constexpr std::size_t kSamples = 600000;  // 10 minutes at 1 kHz

std::vector<double> time_axis() {
  std::vector<double> t(kSamples);
  for (std::size_t k = 0; k < kSamples; ++k) t[k] = static_cast<double>(k) * 1e-3;
  return t;
}

/// A smooth commanded position with a tracking error that has fast content (the worst case for
/// min/max decimation: every bucket has a different extreme).
double position(double t, int axis) { return 50.0 * std::sin(2.0 * std::numbers::pi * 0.013 * (axis + 1) * t); }
double tracking_error(double t, int axis) {
  return 0.01 * std::cos(2.0 * std::numbers::pi * 0.013 * (axis + 1) * t) + 5e-4 * std::sin(611.0 * t + axis);
}

report::Document ten_minute_prediction() {
  const std::vector<double> t = time_axis();
  report::Document doc;
  doc.title = "Prediction of part.nc on fadal-pid";
  report::Section positions{"Positions", "", {}, {}};
  report::Section errors{"Tracking errors", "", {}, {}};
  report::Chart error_chart{"Tracking errors", "time [s]", "error [mm]", report::Scale::Linear, report::Scale::Linear, {}, false};
  for (int axis = 0; axis < 3; ++axis) {
    const std::string name(1, "xyz"[axis]);
    report::Chart chart{"Axis " + name, "time [s]", "position [mm]", report::Scale::Linear, report::Scale::Linear, {}, false};
    report::Series cmd{name + " commanded", t, std::vector<double>(kSamples)};
    report::Series act{name + " predicted", t, std::vector<double>(kSamples)};
    report::Series err{name, t, std::vector<double>(kSamples)};
    for (std::size_t k = 0; k < kSamples; ++k) {
      cmd.y[k] = position(t[k], axis);
      err.y[k] = tracking_error(t[k], axis);
      act.y[k] = cmd.y[k] - err.y[k];
    }
    chart.series = {std::move(cmd), std::move(act)};
    positions.charts.push_back(std::move(chart));
    error_chart.series.push_back(std::move(err));
  }
  errors.charts.push_back(std::move(error_chart));
  report::Chart contour{"Contour error", "time [s]", "contour error [mm]", report::Scale::Linear, report::Scale::Linear, {}, false};
  report::Series ce{"contour error", t, std::vector<double>(kSamples)};
  for (std::size_t k = 0; k < kSamples; ++k) ce.y[k] = std::hypot(tracking_error(t[k], 0), tracking_error(t[k], 1));
  contour.series.push_back(std::move(ce));
  errors.charts.push_back(std::move(contour));
  report::Chart xy{"XY path, error x200", "x [mm]", "y [mm]", report::Scale::Linear, report::Scale::Linear, {}, true};
  report::Series path{"commanded", std::vector<double>(kSamples), std::vector<double>(kSamples)};
  report::Series magnified{"predicted, error x200", std::vector<double>(kSamples), std::vector<double>(kSamples)};
  for (std::size_t k = 0; k < kSamples; ++k) {
    path.x[k] = position(t[k], 0);
    path.y[k] = position(t[k], 1);
    magnified.x[k] = path.x[k] - 200.0 * tracking_error(t[k], 0);
    magnified.y[k] = path.y[k] - 200.0 * tracking_error(t[k], 1);
  }
  xy.series = {std::move(path), std::move(magnified)};
  errors.charts.push_back(std::move(xy));
  doc.sections = {std::move(positions), std::move(errors)};
  return doc;
}

void BM_WriteHtmlTenMinutePrediction(benchmark::State& state) {
  const report::Document doc = ten_minute_prediction();
  std::size_t samples = 0, bytes = 0;
  for (const auto& s : doc.sections)
    for (const auto& c : s.charts)
      for (const auto& series : c.series) samples += series.x.size();
  for (auto _ : state) {
    std::ostringstream out;
    report::write_html(out, doc);
    bytes = static_cast<std::size_t>(out.tellp());
    benchmark::DoNotOptimize(bytes);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(samples));
  state.counters["bytes"] = static_cast<double>(bytes);
  state.counters["series"] = 12;
}
BENCHMARK(BM_WriteHtmlTenMinutePrediction)->Unit(benchmark::kMillisecond);

void BM_DisplayIndices(benchmark::State& state) {
  std::vector<double> y(kSamples);
  for (std::size_t k = 0; k < kSamples; ++k) y[k] = tracking_error(static_cast<double>(k) * 1e-3, 0);
  for (auto _ : state) {
    auto idx = report::display_indices(y, 4000);
    benchmark::DoNotOptimize(idx.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kSamples));
}
BENCHMARK(BM_DisplayIndices)->Unit(benchmark::kMicrosecond);

void BM_DisplayPathIndices(benchmark::State& state) {
  std::vector<double> x(kSamples), y(kSamples);
  for (std::size_t k = 0; k < kSamples; ++k) {
    const double t = static_cast<double>(k) * 1e-3;
    x[k] = position(t, 0) - 200.0 * tracking_error(t, 0);
    y[k] = position(t, 1) - 200.0 * tracking_error(t, 1);
  }
  for (auto _ : state) {
    auto idx = report::display_path_indices(x, y, 2000);
    benchmark::DoNotOptimize(idx.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kSamples));
}
BENCHMARK(BM_DisplayPathIndices)->Unit(benchmark::kMillisecond);

}  // namespace
