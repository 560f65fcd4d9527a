// Prediction of a part program from identified axis models (vcnc::predict): interpolation, three
// axis-model simulations with friction, and the contour error of every sample.
//
// Target (Release, one core): a 10-minute program at 1 kHz on three axes in < 1 s, contour error
// included. The program: helical circles (40 mm, Z descending 0.2 mm per turn), diamonds and
// short lines at F12000, repeated to about 10 minutes; the models are the thesis's Table 3.4 PID
// loop (thesis Eq. 3.3) on every axis.

#include <benchmark/benchmark.h>

#include <string>

#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/machine/presets.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/vcnc/prediction.hpp"

namespace {

using namespace servotwin;

motion::Program ten_minute_program() {
  std::string text = "G17 G90 G01 X20 Y0 Z0 F12000\n";
  double z = 0.0;
  for (int i = 0; i < 330; ++i) {
    z -= 0.2;
    text += "G03 X20 Y0 Z" + std::to_string(z) + " I-20 J0\n";  // a helical turn
    text += "G01 X0 Y20\nG01 X-20 Y0\nG01 X0 Y-20\nG01 X20 Y0\n";  // a diamond
  }
  return motion::parse_iso(text, "bench.nc");
}

std::vector<vcnc::AxisModelSpec> pid_models() {
  // thesis Table 3.4 "actual" closed loop (the fadal-pid preset's X axis)
  const machine::MachineConfig m = machine::preset("fadal-pid");
  const machine::ClosedLoopCoefficients t = machine::equivalent_closed_loop(m.axes.front(), m.ts).coefficients;
  const rapid::ModelCoefficients c{t.a1, t.a2, t.a3, t.b0, t.b1, t.b2, t.d0, t.d1};
  std::vector<vcnc::AxisModelSpec> models;
  for (const char* axis : {"x", "y", "z"}) models.push_back({axis, rapid::AxisModel(c, m.ts), 0, axis});
  return models;
}

void BM_PredictTenMinutes(benchmark::State& state) {
  const motion::Program program = ten_minute_program();
  const auto models = pid_models();
  motion::InterpolationLimits limits;
  limits.accel = 2000.0;
  std::size_t samples = 0;
  for (auto _ : state) {
    const vcnc::Prediction p = vcnc::predict(program, "bench.nc", limits, models);
    samples = p.size();
    benchmark::DoNotOptimize(p.contour_error.data());
  }
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["program_s"] = static_cast<double>(samples) * 0.001;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(samples));
}
BENCHMARK(BM_PredictTenMinutes)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
