// Reading a controller's trace: LinuxCNC halsampler output (blank-separated, sample numbers
// checked) against the same samples as servotwin's capture CSV (the reference, in the same run).
// 600 000 samples (10 minutes at the 1 ms servo rate) of three axes: command, feedback and pid
// output per axis, numbers printed as halsampler prints them ("%f").

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "servotwin/io/capture_csv.hpp"

namespace {

using namespace servotwin;

constexpr std::size_t kSamples = 600'000;

/// The same trace in both layouts: a slow sine per axis, its lagging copy and a force.
std::pair<std::string, std::string> traces() {
  std::string halsampler, csv = "t,x_cmd,x_act,x_u,y_cmd,y_act,y_u,z_cmd,z_act,z_u\n";
  char line[512];
  for (std::size_t k = 0; k < kSamples; ++k) {
    double v[9];
    for (int a = 0; a < 3; ++a) {
      const double t = 1e-3 * static_cast<double>(k);
      v[3 * a] = 10.0 * std::sin(0.5 * t + a);
      v[3 * a + 1] = 10.0 * std::sin(0.5 * (t - 0.004) + a);
      v[3 * a + 2] = 100.0 * std::cos(0.5 * t + a);
    }
    std::snprintf(line, sizeof line, "%zu %f %f %f %f %f %f %f %f %f \n", k, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8]);
    halsampler += line;
    std::snprintf(line, sizeof line, "%.3f,%f,%f,%f,%f,%f,%f,%f,%f,%f\n", 1e-3 * static_cast<double>(k), v[0], v[1], v[2], v[3],
                  v[4], v[5], v[6], v[7], v[8]);
    csv += line;
  }
  return {halsampler, csv};
}

const std::pair<std::string, std::string>& shared_traces() {
  static const auto t = traces();
  return t;
}

void read(benchmark::State& state, const std::string& text, const io::CaptureReadOptions& options) {
  for (auto _ : state) {
    std::istringstream in(text);
    const core::Capture c = io::read_capture_csv(in, "trace", options);
    benchmark::DoNotOptimize(c.axes.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(kSamples));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
}

void BM_ReadHalsampler(benchmark::State& state) {
  io::CaptureReadOptions o;
  o.format = io::TraceFormat::Halsampler;
  o.columns = {"x_cmd", "x_act", "x_u", "y_cmd", "y_act", "y_u", "z_cmd", "z_act", "z_u"};
  o.ts = 0.001;
  read(state, shared_traces().first, o);
}
BENCHMARK(BM_ReadHalsampler)->Unit(benchmark::kMillisecond);

void BM_ReadCaptureCsvReference(benchmark::State& state) { read(state, shared_traces().second, {}); }
BENCHMARK(BM_ReadCaptureCsvReference)->Unit(benchmark::kMillisecond);

}  // namespace
