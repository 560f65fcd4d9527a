// Virtual machine throughput.
//
// Target: >= 5 M samples/s per axis, i.e. a 22 s identification capture at 1 kHz (22 000
// samples) of one axis in under 5 ms, for every controller type with the presets'
// nonlinearities on (friction with stiction, saturation, 16-bit DAC, encoder quantization).
// items/s below count axis-samples, so they are directly "samples/s per axis".

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/machine/presets.hpp"
#include "servotwin/machine/rigid_axis.hpp"
#include "servotwin/machine/simulator.hpp"

namespace {

using namespace servotwin;

// 22 s of random back-and-forth moves within +-10 mm, like the thesis's identification program:
// each move is a smooth (cubic) blend whose duration grows with the distance (<= 200 mm/s).
std::vector<double> identification_like_command(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> target(-10.0, 10.0);
  constexpr double ts = 0.001;
  constexpr std::size_t n = 22000;
  std::vector<double> cmd;
  cmd.reserve(n);
  double from = 0.0;
  while (cmd.size() < n) {
    const double to = target(rng);
    const double duration = std::max(0.02, 1.5 * std::abs(to - from) / 200.0 + 0.02);
    const auto steps = static_cast<std::size_t>(duration / ts);
    for (std::size_t k = 1; k <= steps && cmd.size() < n; ++k) {
      const double u = static_cast<double>(k) / static_cast<double>(steps);
      cmd.push_back(from + (to - from) * u * u * (3.0 - 2.0 * u));
    }
    from = to;
  }
  return cmd;
}

void simulate_preset(benchmark::State& state, const char* name) {
  const machine::MachineConfig m = machine::preset(name);
  const std::vector<std::vector<double>> commands = {identification_like_command(1), identification_like_command(2)};
  for (auto _ : state) {
    core::Capture capture = machine::simulate(m, commands);
    benchmark::DoNotOptimize(capture.axes.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(commands.size() * commands[0].size()));
  state.SetLabel("axis-samples; 22 s capture of 2 axes, nonlinearities on");
}

void BM_SimulatePPi(benchmark::State& state) { simulate_preset(state, "fadal-ppi"); }
void BM_SimulatePid(benchmark::State& state) { simulate_preset(state, "fadal-pid"); }
void BM_SimulateSlidingMode(benchmark::State& state) { simulate_preset(state, "fadal-smc"); }
void BM_SimulatePolePlacementZpetc(benchmark::State& state) { simulate_preset(state, "ballscrew-zpetc"); }
BENCHMARK(BM_SimulatePPi)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimulatePid)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimulateSlidingMode)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SimulatePolePlacementZpetc)->Unit(benchmark::kMillisecond);

// Reference in the same run: the fadal-pid preset's sampled closed loop as a plain difference
// equation (machine::discrete_tracking_tf: linear, no friction, saturation, DAC or encoder), run
// on the same two commands into a capture-sized output: the least one closed-loop axis-sample
// costs, beside the virtual machine with every nonlinearity on (BM_SimulatePid).
void BM_LinearClosedLoopReference(benchmark::State& state) {
  const machine::MachineConfig m = machine::preset("fadal-pid");
  const machine::DiscreteTransferFunction tf = machine::discrete_tracking_tf(m.axes.front(), m.ts);
  // den(z) y = num(z) u, coefficients highest power first: with d = deg den, n = deg num,
  // y[k] = (sum_i num_(n-i) u[k + i - d] - sum_(j<d) den_(d-j) y[k + j - d]) / den_d (a preview,
  // n > d, reads later commands).
  const int d = tf.den.degree(), n = tf.num.degree();
  std::vector<double> num(static_cast<std::size_t>(n + 1)), den(static_cast<std::size_t>(d + 1));
  for (int i = 0; i <= n; ++i) num[static_cast<std::size_t>(i)] = tf.num.coefficient_of_power(i);
  for (int j = 0; j <= d; ++j) den[static_cast<std::size_t>(j)] = tf.den.coefficient_of_power(j);
  const std::vector<std::vector<double>> commands = {identification_like_command(1), identification_like_command(2)};
  for (auto _ : state) {
    std::vector<std::vector<double>> out;
    for (const auto& u : commands) {
      const auto last = static_cast<std::ptrdiff_t>(u.size()) - 1;
      std::vector<double> y(u.size());
      for (std::ptrdiff_t k = 0; k <= last; ++k) {
        double acc = 0.0;
        for (int i = 0; i <= n; ++i) acc += num[static_cast<std::size_t>(i)] * u[static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(k + i - d, 0, last))];
        for (int j = 0; j < d; ++j) {
          const std::ptrdiff_t at = k + j - d;
          acc -= den[static_cast<std::size_t>(j)] * (at >= 0 ? y[static_cast<std::size_t>(at)] : u.front());
        }
        y[static_cast<std::size_t>(k)] = acc / den[static_cast<std::size_t>(d)];
      }
      out.push_back(std::move(y));
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(commands.size() * commands[0].size()));
  state.SetLabel("reference: linear difference equation of the same loop");
}
BENCHMARK(BM_LinearClosedLoopReference)->Unit(benchmark::kMillisecond);

// With encoder noise as well (Box-Muller per sample).
void BM_SimulatePidWithNoise(benchmark::State& state) {
  machine::MachineConfig m = machine::preset("fadal-pid");
  for (auto& a : m.axes) a.nonlinear.encoder_noise_std = 0.0005;
  const std::vector<std::vector<double>> commands = {identification_like_command(1), identification_like_command(2)};
  for (auto _ : state) {
    core::Capture capture = machine::simulate(m, commands);
    benchmark::DoNotOptimize(capture.axes.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(commands.size() * commands[0].size()));
}
BENCHMARK(BM_SimulatePidWithNoise)->Unit(benchmark::kMillisecond);

// The plant kernel alone: exact integration with Coulomb friction through reversals.
void BM_RigidAxisStepWithFriction(benchmark::State& state) {
  machine::Friction f;
  f.coulomb_pos = 44.1;
  f.coulomb_neg = -30.2;
  machine::RigidAxisDynamics axis({0.1, 0.255, 100.0}, f, true, 0.001);
  std::vector<double> u(4096);
  for (std::size_t k = 0; k < u.size(); ++k) u[k] = 2.0 * std::sin(2.0 * 3.141592653589793 * static_cast<double>(k) / 256.0);
  std::size_t k = 0;
  for (auto _ : state) {
    axis.step(u[k++ & 4095]);
    benchmark::DoNotOptimize(axis.position());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RigidAxisStepWithFriction);

}  // namespace
