// Streaming regressors and sufficient statistics of the rapid identification (rapid/regression).
//
// Target: >= 20 M samples/s on one core for the whole pass (ring buffer, stencils, integrated
// error, direction flags, power-of-two column scaling and the blocked Householder update of the
// 9 x 9 factor). items/s = samples. Two captures: the thesis's 22 s at 1 kHz (Table 3.2
// experiment) and a 10 M-sample one (about 3 h at 1 kHz, or 5 min at 32 kHz).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <span>
#include <vector>

#include "servotwin/rapid/regression.hpp"

namespace {

constexpr double kTs = 0.001;

struct Capture {
  std::vector<double> command;
  std::vector<double> actual;
};

/// Random back-and-forth moves (+-10 mm, 200 mm/s, 2000 mm/s^2, trapezoidal velocity) followed by
/// a critically damped second-order loop (25 Hz) and a 0.1 um encoder: data that looks like an
/// identification capture (both directions, reversals, standstills, quantization).
Capture make_capture(std::size_t samples) {
  std::mt19937_64 rng(2007);
  std::uniform_real_distribution<double> target(-10.0, 10.0);
  const double v_max = 200.0;
  const double a_max = 2000.0;
  const double wn = 2.0 * M_PI * 25.0;
  const double q = 1e-4;
  Capture c;
  c.command.resize(samples);
  c.actual.resize(samples);
  double xr = 0.0, vr = 0.0, goal = target(rng);
  double x = 0.0, v = 0.0;
  for (std::size_t k = 0; k < samples; ++k) {
    // Command: accelerate towards the goal, brake in time, pick a new goal on arrival.
    const double distance = goal - xr;
    const double brake = vr * vr / (2.0 * a_max);
    double a = 0.0;
    if (std::abs(distance) < 1e-9 && std::abs(vr) < 1e-9) {
      goal = target(rng);
    } else if (std::abs(distance) <= brake + std::abs(vr) * kTs) {
      a = -std::copysign(std::min(a_max, vr * vr / (2.0 * std::max(std::abs(distance), 1e-12))), vr);
    } else {
      a = std::copysign(a_max, distance);
    }
    vr = std::clamp(vr + a * kTs, -v_max, v_max);
    xr += vr * kTs;
    if ((goal - xr) * std::copysign(1.0, distance) < 0.0) {
      xr = goal;
      vr = 0.0;
    }
    // Axis: semi-implicit Euler of x'' = wn^2 (xr - x) - 2 wn x'.
    v += kTs * (wn * wn * (xr - x) - 2.0 * wn * v);
    x += kTs * v;
    c.command[k] = xr;
    c.actual[k] = q * std::round(x / q);
  }
  return c;
}

const Capture& capture(std::size_t samples) {
  static const Capture short_capture = make_capture(22'000);
  static const Capture long_capture = make_capture(10'000'000);
  return samples == short_capture.command.size() ? short_capture : long_capture;
}

/// Whole capture in one add() call.
void BM_RegressionWhole(benchmark::State& state) {
  const Capture& c = capture(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    servotwin::rapid::RegressorAccumulator acc(kTs, {});
    acc.add(c.command, c.actual);
    benchmark::DoNotOptimize(acc.finish());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_RegressionWhole)->Arg(22'000)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

/// Streamed in 1000-sample chunks (a controller trace arriving in packets), shifted command and
/// trims set: the options that hold samples back in the ring buffer.
void BM_RegressionChunked(benchmark::State& state) {
  const Capture& c = capture(static_cast<std::size_t>(state.range(0)));
  servotwin::rapid::RegressorOptions options;
  options.command_shift = 2;
  options.trim_start = 100;
  options.trim_end = 100;
  const std::size_t chunk = 1000;
  for (auto _ : state) {
    servotwin::rapid::RegressorAccumulator acc(kTs, options);
    for (std::size_t i = 0; i < c.command.size(); i += chunk) {
      const std::size_t n = std::min(chunk, c.command.size() - i);
      acc.add(std::span(c.command).subspan(i, n), std::span(c.actual).subspan(i, n));
    }
    benchmark::DoNotOptimize(acc.finish());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_RegressionChunked)->Arg(22'000)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

}  // namespace
