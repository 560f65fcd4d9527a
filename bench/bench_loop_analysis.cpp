// Velocity-loop indices (loop_analysis.hpp; issue 7, plan §1.6, §1.14).
// Target: a PI design together with its robustness scan <= 10 ms in total, so analyse() of one PI
// loop (2000-point grid, every peak, margins and the step simulations) should stay well under
// 1 ms. choose_omega_star() is a scan of ~40 ω* with a setpoint-weight search at each; it is an
// offline tool and is reported here without a hard target (tens of milliseconds are acceptable).
#include <benchmark/benchmark.h>

#include "servotwin/tuning/loop_analysis.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace {

using namespace servotwin;
using namespace servotwin::tuning;

/// The E26 plant (r = 3, ζz = 0.01) with its ω* = 0.30, ζ* = 1 PI gains.
void BM_AnalysePi(benchmark::State& state) {
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const PidGains gains{4.634937, 0.640260};
  for (auto _ : state) benchmark::DoNotOptimize(analyse(plant, gains));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AnalysePi)->Unit(benchmark::kMicrosecond);

/// The same loop evaluated with a feedback filter τf = 0.01 and a delay 0.15 (Padé order 6): a
/// 12th-order closed loop with a fast pole, so the simulation runs into the sample cap.
void BM_AnalysePiWithHf(benchmark::State& state) {
  NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  plant.hf.feedback_filter_s = 0.01;
  plant.hf.delay_s = 0.15;
  const PidGains gains{4.634937, 0.640260};
  for (auto _ : state) benchmark::DoNotOptimize(analyse(plant, gains));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AnalysePiWithHf)->Unit(benchmark::kMicrosecond);

/// Frequency part only (the simulation capped at 100 samples).
void BM_AnalysePiFrequencyOnly(benchmark::State& state) {
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const PidGains gains{4.634937, 0.640260};
  AnalysisOptions o;
  o.max_samples = 100;
  for (auto _ : state) benchmark::DoNotOptimize(analyse(plant, gains, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AnalysePiFrequencyOnly)->Unit(benchmark::kMicrosecond);

void BM_ChooseOmegaStar(benchmark::State& state) {
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  IndexOptions o;
  o.zeta_star = 1.0;
  o.peak_limit = 1.3;
  for (auto _ : state) benchmark::DoNotOptimize(choose_omega_star(plant, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ChooseOmegaStar)->Unit(benchmark::kMillisecond);

}  // namespace
