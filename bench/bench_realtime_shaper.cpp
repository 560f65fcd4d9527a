// Real-time shaper and discretization benchmarks.
// Target: RealtimeShaper::step <= 50 ns per sample for a 7-pulse shaper (E18's exact
// discretization), i.e. >= 20 M items/s; a drive's 1 kHz..16 kHz loop needs far less.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "servotwin/shaping/discretization.hpp"
#include "servotwin/shaping/realtime_shaper.hpp"
#include "servotwin/shaping/shaped_path.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace {

using namespace servotwin::shaping;

// 7 pulses: ZV4 of a 10 Hz mode at 1 ms, exact decomposition (max delay ~ 130 samples).
DiscreteShaper seven_pulses() {
  return discretize(zv4_shaper(2 * std::numbers::pi * 10.0, 0.05, {0.5, 0.3, 0.0}), 0.001);
}

void BM_RealtimeShaperStep(benchmark::State& state) {
  const DiscreteShaper s = seven_pulses();
  RealtimeShaper f(s);
  double x = 0.0;
  for (auto _ : state) {
    x += 1e-3;
    benchmark::DoNotOptimize(f.step(x));
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["pulses"] = static_cast<double>(f.pulse_count());
}
BENCHMARK(BM_RealtimeShaperStep);

void BM_RealtimeShaperBlock(benchmark::State& state) {
  RealtimeShaper f(seven_pulses());
  std::vector<double> in(4096), out(4096);
  for (std::size_t k = 0; k < in.size(); ++k) in[k] = static_cast<double>(k) * 1e-3;
  for (auto _ : state) {
    f.process(in, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(in.size()));
}
BENCHMARK(BM_RealtimeShaperBlock);

void BM_MultiAxisShaperStep3(benchmark::State& state) {
  const std::vector<double> start{0.0, 0.0, 0.0};
  MultiAxisShaper f(seven_pulses(), start);
  std::vector<double> in{0.0, 1.0, 2.0}, out(3);
  for (auto _ : state) {
    in[0] += 1e-3;
    f.step(in, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_MultiAxisShaperStep3);

void BM_DiscretizeExact(benchmark::State& state) {
  const Shaper s = zv4_shaper(2 * std::numbers::pi * 10.0, 0.05, {0.5, 0.3, 0.0});
  for (auto _ : state) benchmark::DoNotOptimize(discretize(s, 0.001));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DiscretizeExact);

// Contour distortion of a shaped 2-axis trajectory (10^4 samples): the cost of `shaper apply`.
void BM_ShapeAndDeviation(benchmark::State& state) {
  const DiscreteShaper s = seven_pulses();
  const std::size_t n = 10000;
  Columns path(2, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    const double phi = 2 * std::numbers::pi * 2.0 * static_cast<double>(k) * 1e-3;
    path[0][k] = 10.0 * std::cos(phi);
    path[1][k] = 10.0 * std::sin(phi);
  }
  for (auto _ : state) {
    const Columns shaped = shape_columns(path, s);
    benchmark::DoNotOptimize(path_deviation(path, shaped, s.max_delay()).max);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_ShapeAndDeviation);

}  // namespace
