// Per-sample cost of the flexible plant (machine::FlexiblePlant::step), the inner loop of every
// identification experiment on a simulated drive.
// Target: <= 100 ns per sample for the linear two-mass plant (one 4x5 matrix-vector product plus
// the sensor chain); the nonlinear plant (Karnopp friction on both masses + backlash, automatic
// sub-steps) is reported for reference: its cost scales with the sub-step count.

#include <benchmark/benchmark.h>

#include <cmath>

#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/machine/flexible_presets.hpp"

namespace {

using servotwin::machine::FlexiblePlant;
using servotwin::machine::PlantConfig;

PlantConfig linear_two_mass() {
  PlantConfig c;
  c.model = servotwin::machine::two_mass(0.004815, 0.005085, 563.9, 0.0677, 2e-4, 1e-4);
  c.settings.ts = 1.0 / 8000.0;
  c.settings.noise_std = 0.01;
  return c;
}

PlantConfig nonlinear_two_mass() {
  PlantConfig c = servotwin::machine::flexible_preset("motor-bench");  // Karnopp on both masses
  auto& chain = std::get<servotwin::machine::MassChain>(c.model);
  chain.backlash = {2e-4};
  return c;
}

void run(benchmark::State& state, const PlantConfig& config) {
  FlexiblePlant plant(config);
  double phase = 0.0, sink = 0.0;
  for (auto _ : state) {
    phase += 0.05;
    if (phase > 6.283185307179586) phase -= 6.283185307179586;
    sink += plant.step(0.2 * std::sin(phase)).y;
    benchmark::DoNotOptimize(sink);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["substeps"] = plant.substeps();
}

void BM_FlexiblePlantLinearTwoMass(benchmark::State& state) { run(state, linear_two_mass()); }
void BM_FlexiblePlantFrictionBacklash(benchmark::State& state) { run(state, nonlinear_two_mass()); }
void BM_FlexiblePlantTestbed1(benchmark::State& state) { run(state, servotwin::machine::flexible_preset("testbed-1")); }

BENCHMARK(BM_FlexiblePlantLinearTwoMass);
BENCHMARK(BM_FlexiblePlantFrictionBacklash);
BENCHMARK(BM_FlexiblePlantTestbed1);

}  // namespace
