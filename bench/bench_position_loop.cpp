// Multiplicative-uncertainty robustness and the P position loop (catalog C7.9/C7.10, issue-7
// plan §1.7/§1.8) on the E27 case: r = 3, ζz = 0.01, PI (4.63, 0.64), W2 = 2.6 s/(s + 15), M_S = 2.
//
// Targets: robustness() of one loop well below 1 ms (it runs inside every ω* scan step); a PI design
// plus its robustness scan (largest_omega_star_with_uncertainty: admissible range, pole placements,
// RS/NP/RP per step) <= 10 ms; the four Kpp searches of PositionLoop::design() in tens of ms
// (interactive). items_per_second = evaluations (loops, scans, designs) per second.

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"
#include "servotwin/tuning/position_loop.hpp"
#include "servotwin/tuning/uncertainty.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace {

using servotwin::core::Polynomial;
using servotwin::core::TransferFunction;
namespace tuning = servotwin::tuning;

const TransferFunction& weight() {
  static const TransferFunction w2(Polynomial{2.6, 0.0}, Polynomial{1.0, 15.0});
  return w2;
}

const tuning::VelocityLoop& e27_loop() {
  static const tuning::VelocityLoop loop(tuning::normalized_two_mass(3.0, 0.01),
                                         tuning::PidGains{4.63, 0.64, 0.0, 0.0, 1.0, 0.0}, false);
  return loop;
}

void BM_RobustnessOfOneLoop(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(tuning::robustness(e27_loop(), weight(), 2.0));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RobustnessOfOneLoop)->Unit(benchmark::kMicrosecond);

void BM_PiDesignWithRobustnessScan(benchmark::State& state) {
  const tuning::NormalizedPlant plant = tuning::normalized_two_mass(3.0, 0.01);
  for (auto _ : state)
    benchmark::DoNotOptimize(tuning::largest_omega_star_with_uncertainty(plant, 1.0, weight(), 2.0));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PiDesignWithRobustnessScan)->Unit(benchmark::kMillisecond);

void BM_PositionLoopDesign(benchmark::State& state) {
  const tuning::PositionLoop p(tuning::functions_of(e27_loop()), weight());
  for (auto _ : state) benchmark::DoNotOptimize(p.design());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PositionLoopDesign)->Unit(benchmark::kMillisecond);

void BM_EnvelopeFitFirstOrder(benchmark::State& state) {
  std::vector<tuning::ResidualBound> pts;
  for (double w : servotwin::core::log_space(0.1, 1000.0, 60))
    pts.push_back({w, 0.7 * std::abs(weight().frequency_response(w))});
  for (auto _ : state) benchmark::DoNotOptimize(tuning::fit_uncertainty_envelope(pts, 1));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EnvelopeFitFirstOrder)->Unit(benchmark::kMillisecond);

}  // namespace
