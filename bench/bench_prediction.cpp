// Prediction of a part program from identified axis models (vcnc::predict): interpolation, three
// axis-model simulations with friction, and the contour error of every sample. Beside it, in the
// same run, the prediction from a controller's recorded command of the same program
// (vcnc::predict_from_command): the command matched to the programmed path sample by sample, or
// the command's own path (a polyline of 600 000 samples) as the reference, and the trace's
// measured positions scored.
//
// Target (Release, this 2-core machine): a 10-minute program at 1 kHz on three axes in <= 0.1 s,
// contour error included (issue 26; the first target was < 1 s on one core). The program: helical
// circles (40 mm, Z descending 0.2 mm per turn), diamonds and short lines at F12000, repeated to
// about 10 minutes; the models are the thesis's Table 3.4 PID loop (thesis Eq. 3.3) on every axis.

#include <benchmark/benchmark.h>

#include <charconv>
#include <ostream>
#include <streambuf>
#include <string>

#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/machine/presets.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/core/capture.hpp"
#include "servotwin/io/prediction_csv.hpp"
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

/// Arg: worker threads (0 = every core, as `servotwin predict` runs; 1 = the same work on one
/// thread, the reference in the same run). Issue 26 asks <= 0.1 s of computation.
void BM_PredictTenMinutes(benchmark::State& state) {
  const motion::Program program = ten_minute_program();
  const auto models = pid_models();
  motion::InterpolationLimits limits;
  limits.accel = 2000.0;
  vcnc::PredictionOptions options;
  options.workers = static_cast<std::size_t>(state.range(0));
  std::size_t samples = 0;
  for (auto _ : state) {
    const vcnc::Prediction p = vcnc::predict(program, "bench.nc", limits, models, options);
    samples = p.size();
    benchmark::DoNotOptimize(p.contour_error.data());
  }
  state.SetLabel(options.workers == 0 ? "every core" : "one thread");
  state.counters["samples"] = static_cast<double>(samples);
  state.counters["program_s"] = static_cast<double>(samples) * 0.001;
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(samples));
}
BENCHMARK(BM_PredictTenMinutes)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

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
BENCHMARK(BM_PredictTenMinutesFromTheRecordedCommand)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();

/// A stream that keeps nothing but the byte count: the writer's cost without the disk's.
class CountingBuffer : public std::streambuf {
 public:
  std::size_t bytes = 0;

 protected:
  std::streamsize xsputn(const char*, std::streamsize n) override {
    bytes += static_cast<std::size_t>(n);
    return n;
  }
  int_type overflow(int_type c) override {
    ++bytes;
    return c;
  }
};

const vcnc::Prediction& ten_minute_prediction() {
  static const vcnc::Prediction p = [] {
    motion::InterpolationLimits limits;
    limits.accel = 2000.0;
    return vcnc::predict(ten_minute_program(), "bench.nc", limits, pid_models());
  }();
  return p;
}

/// `predict -o`'s CSV of the ten-minute prediction (about 600 000 rows of three axes): Arg 0 the
/// writer (io::write_prediction_csv), Arg 1 the reference in the same run, the same numbers
/// formatted shortest round-trip by std::to_chars into one buffer with nothing else (the least a
/// CSV writer can cost). Issue 26 asks >= 200 MB/s.
void BM_WritePredictionCsv(benchmark::State& state) {
  const vcnc::Prediction& p = ten_minute_prediction();
  std::size_t bytes = 0;
  std::string reference;
  for (auto _ : state) {
    if (state.range(0) == 0) {
      CountingBuffer counter;
      std::ostream out(&counter);
      io::write_prediction_csv(out, p, nullptr);
      bytes = counter.bytes;
    } else {
      reference.clear();
      char field[32];
      for (std::size_t k = 0; k < p.size(); ++k) {
        const auto put = [&](double v) {
          const auto r = std::to_chars(field, field + sizeof field, v);
          reference.append(field, r.ptr);
          reference.push_back(',');
        };
        put(static_cast<double>(k) * p.ts);
        for (std::size_t i = 0; i < p.axes.size(); ++i) {
          put(p.command[i][k]);
          put(p.predicted[i][k]);
          put(p.tracking_error(i, k));
        }
        put(p.contour_error[k]);
        reference.append("line\n");
      }
      bytes = reference.size();
      benchmark::DoNotOptimize(reference.data());
    }
  }
  state.SetLabel(state.range(0) == 0 ? "io::write_prediction_csv" : "reference: std::to_chars into one buffer");
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes));
}
BENCHMARK(BM_WritePredictionCsv)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
