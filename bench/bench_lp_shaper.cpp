// Direct LP synthesis of multi-mode shapers (catalog C6.4). Target (issue): one multi-mode LP
// design <= 10 ms (E22: 3 modes, ZV + zero slope, n = 14). The C6.4 grid search over Tp = j·T is
// reported too (no target in the issue; E22's modes with T = 0.01 s try 315 spacings up to
// π/ω_d1 with up to ~2200 impulses each).
#include <benchmark/benchmark.h>

#include <vector>

#include "servotwin/shaping/lp_shaper.hpp"

namespace {

using namespace servotwin::shaping;

const std::vector<LpMode> kModes = {{1.0, 0.1}, {2.25, 0.1}, {3.4, 0.1}};

LpShaperOptions e22_options(int n) {
  LpShaperOptions o;
  o.pulse_spacing = 0.68;
  o.pulse_count = n;
  o.derivative_order = 1;
  return o;
}

// E22 on its fixed grid (n = 14, Tp = 0.68 s).
void BM_LpDesignE22(benchmark::State& state) {
  const LpShaperOptions o = e22_options(14);
  for (auto _ : state) benchmark::DoNotOptimize(lp_shaper(kModes, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LpDesignE22)->Unit(benchmark::kMicrosecond);

// E23: ZV + 6 sensitivity bounds (n = 14, Tp = 0.63 s).
void BM_LpDesignE23(benchmark::State& state) {
  LpShaperOptions o;
  o.pulse_spacing = 0.63;
  o.pulse_count = 14;
  for (const LpMode& m : kModes)
    for (double r : {0.85, 1.15}) o.bounds.push_back({r * m.omega, m.zeta, 0.05});
  for (auto _ : state) benchmark::DoNotOptimize(lp_shaper(kModes, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LpDesignE23)->Unit(benchmark::kMicrosecond);

// E22 at Tp = 0.68 s with the smallest n searched (pulse_count = 0: bisection up to the cap).
void BM_LpDesignE22MinimalN(benchmark::State& state) {
  const LpShaperOptions o = e22_options(0);
  for (auto _ : state) benchmark::DoNotOptimize(lp_shaper(kModes, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LpDesignE22MinimalN)->Unit(benchmark::kMicrosecond);

// One fine-grid design: Tp = T = 0.01 s, n = 880 (the minimal n there is ~870).
void BM_LpDesignFineGrid(benchmark::State& state) {
  LpShaperOptions o = e22_options(880);
  o.pulse_spacing = 0.01;
  for (auto _ : state) benchmark::DoNotOptimize(lp_shaper(kModes, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LpDesignFineGrid)->Unit(benchmark::kMillisecond);

// The full C6.4 search, items = spacings tried. Arg = T in ms (50: 63 spacings, 10: 315).
void BM_LpSearchE22(benchmark::State& state) {
  LpShaperOptions base;
  base.derivative_order = 1;
  LpSearchOptions search;
  search.sample_period = static_cast<double>(state.range(0)) * 1e-3;
  std::size_t spacings = 0;
  for (auto _ : state) {
    const std::vector<LpCandidate> found = lp_shaper_search(kModes, base, search);
    spacings = found.size();
    benchmark::DoNotOptimize(found.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(spacings));
}
BENCHMARK(BM_LpSearchE22)->Arg(50)->Arg(10)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
