// Solvers of the constrained identification problem (rapid/solver.hpp).
//
// Targets (Release, one core):
//  - exact <= 2 ms on thesis-like problems, both with active bounds (Table 3.1 case 2, and a fold
//    of the pole parametrization) and interior (case 1);
//  - ga with the thesis's settings (population 4000, 500 generations) <= 1 s;
//  - ls: microseconds (one reduction and a 3 x 3 solve).
// The problems are simulated identification runs (Table 4.1's PID drive, 60 random moves of
// +-10 mm at up to 200 mm/s, 1 um encoder quantization, 1 kHz): 10 000 regressor rows reduced to
// the 9 x 9 factor beforehand, so only the solver is timed. items/s count solves.

#include <benchmark/benchmark.h>

#include "../tests/rapid/test_solver_support.hpp"
#include "servotwin/rapid/solver.hpp"

namespace {

using namespace servotwin::rapid;

const RegressionProblem& thesis_problem() {
  static const RegressionProblem problem = test::thesis_like_problem(test::thesis_pid_drive(), 11);
  return problem;
}

Bounds bounds_for(int which) {
  Bounds b = default_bounds(1e-3);
  if (which == 1) b.zeta_min = 0.6;              // zeta_min active (case 2)
  if (which == 2) b.wn_max = test::kTwoPi * 25;  // optimum on the fold (three real poles)
  return b;
}

void BM_Exact(benchmark::State& state) {
  const Bounds b = bounds_for(static_cast<int>(state.range(0)));
  Solution s;
  for (auto _ : state) {
    s = solve(thesis_problem(), Method::Exact, b);
    benchmark::DoNotOptimize(s.objective);
  }
  state.counters["boxes"] = static_cast<double>(s.boxes);
  state.counters["certified"] = s.certified ? 1.0 : 0.0;
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(s.kkt_case.substr(0, 24));
}
BENCHMARK(BM_Exact)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_Ga(benchmark::State& state) {
  const Bounds b = bounds_for(static_cast<int>(state.range(0)));
  SolveOptions o;  // thesis settings: 4000 candidates, 500 generations, rates 0.5 / 0.05, top 5
  for (auto _ : state) {
    const Solution s = solve(thesis_problem(), Method::Ga, b, o);
    benchmark::DoNotOptimize(s.objective);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Ga)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_Ls(benchmark::State& state) {
  const Bounds b = bounds_for(0);
  for (auto _ : state) {
    const Solution s = solve(thesis_problem(), Method::Ls, b);
    benchmark::DoNotOptimize(s.objective);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Ls)->Unit(benchmark::kMicrosecond);

}  // namespace
