// AxisModel::simulate throughput. Targets: >= 10 M samples/s with friction switching (first
// issue), >= 50 M samples/s for every model with reused outputs (issue 26, including a model
// faster than the sampling), on a thesis-like 22 s identification command at 1 kHz and on a
// 10-minute command, allocating only the three output vectors. References in the same run:
// core::simulate_zoh of the same linear system (the generic ZOH simulator; no friction), and the
// simulation with the series event search on every sample (ModelSimulationOptions::
// event_search_every_sample), which the certified single steps must equal.
//
// Commands: random back-and-forth trapezoidal moves (std::mt19937_64, seed 7): targets uniform in
// [0, 100] mm, feeds uniform in [10, 200] mm/s, acceleration 2000 mm/s^2, dwells of 0-50 ms, so a
// 22 s command has ~90 reversals and stops (each located by the event search).
//
// Counters: items_per_second = samples/s; allocs = heap allocations per call (glibc malloc
// interposed in this executable): 3 for simulate() (the output vectors), 0 for simulate_into()
// with reused outputs.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

#include "servotwin/core/state_space.hpp"
#include "servotwin/rapid/axis_model.hpp"

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
#define SERVOTWIN_COUNT_MALLOC 1
extern "C" void* __libc_malloc(std::size_t size);  // NOLINT: glibc's implementation
namespace {
std::size_t malloc_calls = 0;
}
extern "C" void* malloc(std::size_t size) noexcept {  // counts every heap allocation
  ++malloc_calls;
  return __libc_malloc(size);
}
#endif

namespace {

using servotwin::rapid::AxisModel;
using servotwin::rapid::ModelCoefficients;
using servotwin::rapid::ModelResponse;

constexpr double kTs = 1e-3;

std::vector<double> random_moves(double seconds) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> target(0.0, 100.0), feed(10.0, 200.0), dwell(0.0, 0.05);
  const double accel = 2000.0;
  const auto n = static_cast<std::size_t>(seconds / kTs);
  std::vector<double> out;
  out.reserve(n);
  double x = 50.0;
  while (out.size() < n) {
    const double to = target(rng), v = feed(rng), d = std::abs(to - x), sign = to > x ? 1.0 : -1.0;
    double ta = v / accel, vp = v, tc = (d - accel * ta * ta) / v;
    if (tc < 0.0) {
      ta = std::sqrt(d / accel);
      vp = accel * ta;
      tc = 0.0;
    }
    const double total = 2.0 * ta + tc;
    for (double t = 0.0; t < total && out.size() < n; t += kTs) {
      double p;
      if (t < ta) p = 0.5 * accel * t * t;
      else if (t < ta + tc) p = 0.5 * accel * ta * ta + vp * (t - ta);
      else p = d - 0.5 * accel * (total - t) * (total - t);
      out.push_back(x + sign * p);
    }
    x = to;
    for (double t = 0.0; t < dwell(rng) && out.size() < n; t += kTs) out.push_back(x);
  }
  return out;
}

// Thesis Table 3.4, PID X axis (actual), and Table 3.3, P-PI X axis (actual).
const ModelCoefficients kPid{.a1 = 192.65, .a2 = 44356.23, .a3 = 316830.21, .b0 = 0.0, .b1 = 190.10,
                             .b2 = 44356.23, .d0 = 441.0, .d1 = -302.0};
const ModelCoefficients kPpi{.a1 = 372.76, .a2 = 62009.83, .a3 = 1527104.87, .b0 = 0.0, .b1 = 0.0,
                             .b2 = 11106.33, .d0 = 441.0, .d1 = -302.0};

// A model faster than the sample rate at 1 kHz (issue 26: the 1 M-sample capture's fit): a pair at
// 143 Hz with damping 0.2 and a real pole at 0.2 Hz, s^3 + a1 s^2 + a2 s + a3 =
// (s + p)(s^2 + 2 zeta w s + w^2), PID structure (b2 = a2, b1 = 2 zeta w), the thesis's friction.
ModelCoefficients fast_pair_model() {
  const double w = 2.0 * 3.141592653589793 * 143.0, zeta = 0.2, p = 2.0 * 3.141592653589793 * 0.2;
  return {.a1 = 2.0 * zeta * w + p, .a2 = w * w + 2.0 * zeta * w * p, .a3 = p * w * w, .b0 = 0.0,
          .b1 = 2.0 * zeta * w, .b2 = w * w + 2.0 * zeta * w * p, .d0 = 441.0, .d1 = -302.0};
}

// reuse = false: simulate() allocates fresh outputs each call (page faults of fresh memory are
// part of that cost); reuse = true: simulate_into() into the same ModelResponse (no allocation).
void run_simulation(benchmark::State& state, const ModelCoefficients& coefficients, double seconds, bool reuse,
                    bool event_search_every_sample = false) {
  const std::vector<double> command = random_moves(seconds);
  const AxisModel model(coefficients, kTs);
  servotwin::rapid::ModelSimulationOptions options;
  options.event_search_every_sample = event_search_every_sample;
  ModelResponse kept;
  std::uint64_t reversals = 0;
  double allocations = 0.0;
  for (auto _ : state) {
#ifdef SERVOTWIN_COUNT_MALLOC
    const std::size_t before = malloc_calls;
#endif
    if (reuse) {
      model.simulate_into(command, kept, options);
      reversals = kept.events.reversals;
      benchmark::DoNotOptimize(kept.position.data());
    } else {
      ModelResponse r = model.simulate(command, options);
      reversals = r.events.reversals;
      benchmark::DoNotOptimize(r.position.data());
    }
#ifdef SERVOTWIN_COUNT_MALLOC
    allocations = static_cast<double>(malloc_calls - before);
#endif
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(command.size()));
  state.counters["reversals"] = static_cast<double>(reversals);
  state.counters["allocs"] = allocations;
}

ModelCoefficients without_friction(ModelCoefficients c) {
  c.d0 = c.d1 = 0.0;  // d0 == d1: the plain ZOH path
  return c;
}

void BM_SimulatePidFriction22s(benchmark::State& state) { run_simulation(state, kPid, 22.0, false); }
void BM_SimulatePidFriction22sReused(benchmark::State& state) { run_simulation(state, kPid, 22.0, true); }
void BM_SimulatePpiFriction22sReused(benchmark::State& state) { run_simulation(state, kPpi, 22.0, true); }
void BM_SimulatePidLinear22sReused(benchmark::State& state) { run_simulation(state, without_friction(kPid), 22.0, true); }
void BM_SimulateFastPairFriction22sReused(benchmark::State& state) {
  run_simulation(state, fast_pair_model(), 22.0, true);
}
// The reference the certified steps are tested against: the series event search on every sample
// (what every sample of a model faster than the sampling cost before issue 26).
void BM_SimulateFastPairFriction22sEverySample(benchmark::State& state) {
  run_simulation(state, fast_pair_model(), 22.0, true, true);
}
void BM_SimulatePidFriction22sEverySample(benchmark::State& state) { run_simulation(state, kPid, 22.0, true, true); }
void BM_SimulatePidFriction10min(benchmark::State& state) { run_simulation(state, kPid, 600.0, false); }
void BM_SimulatePidFriction10minReused(benchmark::State& state) { run_simulation(state, kPid, 600.0, true); }

// Baseline: the generic core simulator on the same linear system (inputs x_r, x_r', x_r'').
void BM_CoreSimulateZohBaseline22s(benchmark::State& state) {
  const std::vector<double> command = random_moves(22.0);
  const auto n = static_cast<Eigen::Index>(command.size());
  Eigen::MatrixXd u(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto at = [&](Eigen::Index j) { return command[static_cast<std::size_t>(std::clamp<Eigen::Index>(j, 0, n - 1))]; };
    u(k, 0) = at(k);
    u(k, 1) = (at(k + 1) - at(k - 1)) / (2 * kTs);
    u(k, 2) = (at(k + 2) - 2 * at(k) + at(k - 2)) / (4 * kTs * kTs);
  }
  servotwin::core::StateSpace sys;
  sys.A = Eigen::MatrixXd(3, 3);
  sys.A << 0, 1, 0, -kPid.a2, -kPid.a1, kPid.a3, -1, 0, 0;
  sys.B = Eigen::MatrixXd::Zero(3, 3);
  sys.B.row(1) << kPid.b2, kPid.b1, kPid.b0;
  sys.B(2, 0) = 1.0;
  sys.C = Eigen::MatrixXd::Zero(1, 3);
  sys.C(0, 0) = 1.0;
  sys.D = Eigen::MatrixXd::Zero(1, 3);
  for (auto _ : state) {
    Eigen::MatrixXd y = servotwin::core::simulate_zoh(sys, u, kTs);
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(command.size()));
}

}  // namespace

BENCHMARK(BM_SimulatePidFriction22s)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SimulatePidFriction22sReused)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SimulatePpiFriction22sReused)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SimulateFastPairFriction22sReused)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SimulateFastPairFriction22sEverySample)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SimulatePidFriction22sEverySample)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SimulatePidLinear22sReused)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CoreSimulateZohBaseline22s)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SimulatePidFriction10min)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimulatePidFriction10minReused)->Unit(benchmark::kMillisecond);
