// Kernels of servotwin::core that run inside loops of the identification and simulation code.
//
// Targets (Release build, one core of the 2-core reference machine):
//  * frequency response of a 4-state transfer function on 1000 frequencies: < 50 us (an FRF plot
//    or a fit residual evaluates it many times);
//  * discrete simulation of a 4-state system for 1e5 steps: python-control needs 0.56-0.84 s for
//    this, servotwin must be >= 100x faster, i.e. < 5.6 ms per 1e5 steps (< 56 ns per step). The
//    per-step path (DiscreteSimulator::step) does not allocate (tests/core/allocation_test.cpp).
//  * roots of the thesis's closed-loop cubic: < 20 us (computed per candidate model in fits).

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "servotwin/core/hinf.hpp"
#include "servotwin/core/model_reduction.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace {

using servotwin::core::DiscreteSimulator;
using servotwin::core::DiscreteStateSpace;
using servotwin::core::Polynomial;
using servotwin::core::StateSpace;
using servotwin::core::TransferFunction;

// Two-mass drive: J1 = 1e-3, J2 = 2e-3 kg m^2, shaft k = 500 N m/rad, c = 0.05 N m s/rad.
constexpr double kJ1 = 1e-3, kJ2 = 2e-3, kK = 500.0, kC = 0.05;

/// Motor torque -> motor angle, 4 states: (J2 s^2 + c s + k) / (s^2 (J1 J2 s^2 + c (J1+J2) s + k (J1+J2))).
TransferFunction two_mass_motor_angle() {
  return {Polynomial{kJ2, kC, kK}, Polynomial{kJ1 * kJ2, kC * (kJ1 + kJ2), kK * (kJ1 + kJ2), 0.0, 0.0}};
}

/// States [theta1, omega1, theta2, omega2], outputs [omega1, theta2].
StateSpace two_mass_ss() {
  StateSpace s;
  s.A = Eigen::MatrixXd{{0.0, 1.0, 0.0, 0.0},
                        {-kK / kJ1, -kC / kJ1, kK / kJ1, kC / kJ1},
                        {0.0, 0.0, 0.0, 1.0},
                        {kK / kJ2, kC / kJ2, -kK / kJ2, -kC / kJ2}};
  s.B = Eigen::MatrixXd{{0.0}, {1.0 / kJ1}, {0.0}, {0.0}};
  s.C = Eigen::MatrixXd{{0.0, 1.0, 0.0, 0.0}, {0.0, 0.0, 1.0, 0.0}};
  s.D = Eigen::MatrixXd::Zero(2, 1);
  return s;
}

/// A switching torque (deterministic square wave with 20-sample period).
Eigen::MatrixXd square_wave(Eigen::Index samples) {
  Eigen::MatrixXd u(samples, 1);
  for (Eigen::Index k = 0; k < samples; ++k) u(k, 0) = ((k / 10) % 2 == 0) ? 0.05 : -0.05;
  return u;
}

void BM_FrequencyResponse4State1000Points(benchmark::State& state) {
  const TransferFunction g = two_mass_motor_angle();
  const std::vector<double> omega = servotwin::core::log_space(1.0, 1e5, 1000);
  for (auto _ : state) {
    std::vector<std::complex<double>> h = g.frequency_response(omega);
    benchmark::DoNotOptimize(h.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(omega.size()));
}
BENCHMARK(BM_FrequencyResponse4State1000Points)->Unit(benchmark::kMicrosecond);

void BM_Simulate4State1e5Steps(benchmark::State& state) {
  const DiscreteStateSpace d = servotwin::core::discretize_zoh(two_mass_ss(), 1e-3);
  const Eigen::MatrixXd u = square_wave(100000);
  for (auto _ : state) {
    Eigen::MatrixXd y = servotwin::core::simulate(d, u);
    benchmark::DoNotOptimize(y.data());
  }
  state.SetItemsProcessed(state.iterations() * u.rows());
}
BENCHMARK(BM_Simulate4State1e5Steps)->Unit(benchmark::kMillisecond);

void BM_DiscreteSimulatorStep4State1e5Steps(benchmark::State& state) {
  DiscreteSimulator sim(servotwin::core::discretize_zoh(two_mass_ss(), 1e-3));
  constexpr int steps = 100000;
  double out[2] = {0.0, 0.0};
  for (auto _ : state) {
    sim.reset();
    for (int k = 0; k < steps; ++k) {
      const double u = ((k / 10) % 2 == 0) ? 0.05 : -0.05;
      sim.step(std::span<const double>(&u, 1), out);
      benchmark::DoNotOptimize(out);
    }
  }
  state.SetItemsProcessed(state.iterations() * steps);
}
BENCHMARK(BM_DiscreteSimulatorStep4State1e5Steps)->Unit(benchmark::kMillisecond);

void BM_DiscretizeZoh4State(benchmark::State& state) {
  const StateSpace s = two_mass_ss();
  for (auto _ : state) {
    DiscreteStateSpace d = servotwin::core::discretize_zoh(s, 1e-3);
    benchmark::DoNotOptimize(d.A.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DiscretizeZoh4State)->Unit(benchmark::kMicrosecond);

void BM_RootsThesisCubic(benchmark::State& state) {
  const Polynomial p{1.0, 372.76, 62009.83, 1527104.87};
  for (auto _ : state) {
    auto r = p.roots();
    benchmark::DoNotOptimize(r.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RootsThesisCubic)->Unit(benchmark::kMicrosecond);

void BM_RootsTripleRoot(benchmark::State& state) {
  const Polynomial p{1.0, 5.0, 9.0, 7.0, 2.0};  // (s+1)^3 (s+2): exercises cluster detection
  for (auto _ : state) {
    auto r = p.roots();
    benchmark::DoNotOptimize(r.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RootsTripleRoot)->Unit(benchmark::kMicrosecond);

/// Balanced truncation of a 5-mode drive (10 states, lightly damped) to 4 states: the model
/// reduction of a multi-mode plant or controller (C7.16), a design-time step. Target: < 1 ms.
void BM_BalancedTruncation10To4States(benchmark::State& state) {
  servotwin::core::StateSpace g;
  const int modes = 5;
  g.A = Eigen::MatrixXd::Zero(2 * modes, 2 * modes);
  g.B = Eigen::MatrixXd::Zero(2 * modes, 1);
  g.C = Eigen::MatrixXd::Zero(1, 2 * modes);
  g.D = Eigen::MatrixXd::Zero(1, 1);
  for (int i = 0; i < modes; ++i) {
    const double w = std::pow(3.0, i), z = 0.02 + 0.01 * i;
    g.A(2 * i, 2 * i + 1) = 1.0;
    g.A(2 * i + 1, 2 * i) = -w * w;
    g.A(2 * i + 1, 2 * i + 1) = -2.0 * z * w;
    g.B(2 * i + 1, 0) = 1.0;
    g.C(0, 2 * i) = w * w / (1.0 + i);
  }
  for (auto _ : state) {
    auto r = servotwin::core::balanced_truncation(g, 4);
    benchmark::DoNotOptimize(r.error_bound);
  }
}
BENCHMARK(BM_BalancedTruncation10To4States)->Unit(benchmark::kMicrosecond);

/// The same reduction of an unstable controller (C7.19's printed H-infinity controller, with an
/// integrator and an unstable pair, times three lightly damped stable modes: 11 states, 8 stable)
/// to 7 states: the stable/unstable split (ordered Schur form, Sylvester equation) and the
/// truncation of the stable part (C7.16's controller reduction). Target: < 1 ms.
void BM_BalancedTruncationUnstable11To7States(benchmark::State& state) {
  using servotwin::core::Polynomial;
  Polynomial num = -0.067 * (Polynomial{1.0, -146.0} * Polynomial{1.0, 0.27} * Polynomial{1.0, 0.52, 2.02});
  Polynomial den = Polynomial{1.0, 0.0} * Polynomial{1.0, -0.96, 2.9} * Polynomial{1.0, 22.35, 274.2};
  for (const double w : {3.0, 7.0, 15.0}) {
    num = num * Polynomial{1.0, 0.01 * w, w * w};
    den = den * Polynomial{1.0, 0.05 * w, w * w};
  }
  const servotwin::core::StateSpace g = servotwin::core::to_state_space(servotwin::core::TransferFunction(num, den));
  for (auto _ : state) {
    auto r = servotwin::core::balanced_truncation_stable_part(g, 7);
    benchmark::DoNotOptimize(r.error_bound);
  }
}
BENCHMARK(BM_BalancedTruncationUnstable11To7States)->Unit(benchmark::kMicrosecond);

/// H-infinity synthesis of a 4-state MIMO problem with every D11 block non-zero and D22 != 0 (the
/// core test's mimo_general): the gamma iteration to 1e-4 with the closed loop checked near the
/// optimum. The mixed-sensitivity designs call it once per weight choice. Target: < 5 ms.
void BM_HinfSynthesisMimo(benchmark::State& state) {
  servotwin::core::StateSpace p;
  p.A.resize(4, 4);
  p.A << 0.5, 1, 0, 0, -1, -0.2, 0.3, 0, 0, 0, -2, 1, 0.2, 0, 0, -1;
  p.B.resize(4, 3);
  p.B << 1, 0, 0, 0, 0.5, 1, 0.3, 0, 0, 0, 1, 0.5;
  p.C.resize(3, 4);
  p.C << 1, 0, 0.5, 0, 0, 0, 0, 0.2, 0, 1, 0, 1;
  p.D.resize(3, 3);
  p.D << 0.1, 0.2, 0.3, 0.05, 0.3, 1, 0.2, 1, 0.4;
  for (auto _ : state) {
    auto s = servotwin::core::hinf_synthesis(p, 1, 1);
    benchmark::DoNotOptimize(s.gamma_optimal);
  }
}
BENCHMARK(BM_HinfSynthesisMimo)->Unit(benchmark::kMicrosecond);

}  // namespace
