// Prediction of a part program from identified axis models (vcnc::predict): interpolation, three
// axis-model simulations with friction, and the contour error of every sample. Beside it, in the
// same run, the prediction from a controller's recorded command of the same program
// (vcnc::predict_from_command): the command matched to the programmed path sample by sample, or
// the command's own path (a polyline of 600 000 samples) as the reference, and the trace's
// measured positions scored.
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
#include "servotwin/core/capture.hpp"
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

/// The ten-minute program's prediction as a controller's trace: its command, and the predicted
/// positions standing in for the measured ones.
core::Capture ten_minute_trace(const motion::Program& program, const std::vector<vcnc::AxisModelSpec>& models) {
  motion::InterpolationLimits limits;
  limits.accel = 2000.0;
  const vcnc::Prediction p = vcnc::predict(program, "bench.nc", limits, models);
  core::Capture trace;
  trace.ts = p.ts;
  for (std::size_t i = 0; i < p.axes.size(); ++i) trace.axes.push_back({motion::axis_name(p.axes[i]), p.command[i], p.predicted[i], {}});
  return trace;
}

void BM_PredictTenMinutesFromTheRecordedCommand(benchmark::State& state) {
  const motion::Program program = ten_minute_program();
  const auto models = pid_models();
  const core::Capture trace = ten_minute_trace(program, models);
  const bool with_program = state.range(0) == 1;
  for (auto _ : state) {
    const vcnc::Prediction p =
        vcnc::predict_from_command(trace, "trace", with_program ? &program : nullptr, "bench.nc", models);
    const vcnc::MeasuredComparison m = vcnc::compare_with_trace(p, trace, "trace");
    benchmark::DoNotOptimize(m.scores.data());
  }
  state.SetLabel(with_program ? "against the program's path" : "against the command's own path");
  state.counters["samples"] = static_cast<double>(trace.size());
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(trace.size()));
}
BENCHMARK(BM_PredictTenMinutesFromTheRecordedCommand)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
