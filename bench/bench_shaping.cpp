// Single-mode shaper design times. Target (issue): any single-mode design <= 10 µs.
#include <benchmark/benchmark.h>

#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/smoothing.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace {

using namespace servotwin::shaping;

void BM_Zv4Design(benchmark::State& state) {
  double omega = 26.5;
  for (auto _ : state) {
    benchmark::DoNotOptimize(zv4_shaper(omega, 0.0079, {0.3, 0.5, 0.0}));
    omega += 1e-9;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Zv4Design);

void BM_FamilyDesign(benchmark::State& state) {
  const auto type = static_cast<ShaperType>(state.range(0));
  state.SetLabel(std::string(to_string(type)));
  double omega = 314.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(design_shaper(type, omega, 0.1));
    omega += 1e-9;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FamilyDesign)->DenseRange(0, 6);

void BM_ResidualVibration(benchmark::State& state) {
  const Shaper s = zv4_shaper(26.5, 0.0079, {0.3, 0.5, 0.0});
  double omega = 20.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(residual_vibration(s, omega, 0.01));
    omega += 1e-9;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ResidualVibration);

void BM_Smoothing(benchmark::State& state) {
  const Shaper s = mzv_shaper(314.0, 0.1);
  for (auto _ : state) benchmark::DoNotOptimize(shaper_smoothing(s));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Smoothing);

}  // namespace
