// Closed-loop verification run (vcnc::simulate_drive): a PI tuned for the motor-bench preset (two-mass
// servo with Karnopp friction on both masses, current lag, encoder-step quantization, noise; 8 kHz)
// runs a velocity step on the plant and on its linear part. The cost is dominated by the nonlinear
// plant's sub-steps (8 per sample here); per loop sample (plant + linear twin + controller) it should
// stay near the plant's own per-sample cost (bench_flexible_plant), a few hundred ns: one second of
// drive time in a few milliseconds.
#include <benchmark/benchmark.h>

#include "servotwin/fit/plant_model.hpp"
#include "servotwin/machine/flexible_frame.hpp"
#include "servotwin/machine/flexible_presets.hpp"
#include "servotwin/tuning/tune.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"
#include "servotwin/vcnc/frame_sequence.hpp"

namespace {

using namespace servotwin;

void BM_DriveSimulationMotorBench(benchmark::State& state) {
  const machine::PlantConfig plant = machine::flexible_preset("motor-bench");
  const auto tf = machine::mass_chain_transfer_function(std::get<machine::MassChain>(plant.model),
                                                        machine::PlantOutput::MotorVelocity);
  const tuning::Controller controller = tuning::tune(fit::plant_model_from_transfer_function(tf), {}).controller;
  vcnc::DriveSimulationSettings settings;
  settings.duration_s = 1.0;
  settings.amplitude = 10.0;
  std::size_t samples = 0;
  for (auto _ : state) {
    const vcnc::DriveSimulation sim = vcnc::simulate_drive(plant, controller, settings);
    samples = sim.samples.size();
    benchmark::DoNotOptimize(sim.metrics.itae);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(samples));
}
BENCHMARK(BM_DriveSimulationMotorBench)->Unit(benchmark::kMillisecond);


// The flexible-frame test of C7.19 (vcnc::simulate_frame_sequence): the tuner's PI on the frame's
// 7-state model, 45 s at 10 ms (4501 samples) plus the closed loop's modal decomposition. Target:
// about a millisecond per run (0.8 ms measured), so a study sweeps hundreds of designs in a second.
void BM_FrameSequencePi(benchmark::State& state) {
  const machine::FlexibleFrame frame = machine::c7_19_flexible_frame();
  const tuning::Controller controller =
      tuning::tune(fit::plant_model_from_transfer_function(machine::flexible_frame_transfer_function(frame)), {})
          .controller;
  const core::StateSpace k = tuning::controller_state_space(controller);
  for (auto _ : state) {
    const vcnc::FrameSequence run = vcnc::simulate_frame_sequence(frame, k);
    benchmark::DoNotOptimize(run.phases[2].residual_stator);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 4501);
}
BENCHMARK(BM_FrameSequencePi)->Unit(benchmark::kMicrosecond);

}  // namespace
