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

// Target: any single-mode design <= 10 us (issue 6). The dampings cycle through values between the
// EI family's tabulated nodes (every 0.02), so the measured time includes the interpolation and
// the Newton/chord correction a real design pays.
void BM_FamilyDesign(benchmark::State& state) {
  const auto type = static_cast<ShaperType>(state.range(0));
  state.SetLabel(std::string(to_string(type)));
  constexpr double kZetas[] = {0.013, 0.057, 0.1, 0.113, 0.171, 0.029};
  double omega = 314.0;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(design_shaper(type, omega, kZetas[i]));
    i = (i + 1) % std::size(kZetas);
    omega += 1e-9;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FamilyDesign)->DenseRange(0, 6);

// The first EI-family design for a new vibration tolerance builds the family's table of exact
// solutions (continuation from the undamped closed form): the one-time cost.
void BM_EiFamilyFirstDesign(benchmark::State& state) {
  const auto type = static_cast<ShaperType>(state.range(0));
  state.SetLabel(std::string(to_string(type)));
  double v_tol = 0.03;
  for (auto _ : state) {
    benchmark::DoNotOptimize(design_shaper(type, 314.0, 0.1, v_tol));
    v_tol += 1e-7;  // a new tolerance every time: a new table
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EiFamilyFirstDesign)->DenseRange(4, 6);

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
