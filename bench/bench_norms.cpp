// Peak-gain and stability kernels of servotwin::core used inside controller-tuning searches
// (issue 7: every candidate gain set is scored by H-infinity norms / grid peaks and screened by
// Routh tests, thousands of times per design).
//
// Targets (Release build, one core of the 2-core reference machine):
//  * hinf_norm of a 10-state lightly damped SISO system (5 modes, zeta 0.01-0.02), rel_tol 1e-6:
//    <= 200 us per call;
//  * peak_on_grid on 2000 log-spaced points of a 4th-order transfer function (with the golden-section
//    refinement of its local maxima): no hard target, reported per call and per grid point;
//  * is_hurwitz (Routh array) of a degree-6 polynomial: <= 100 ns per call (the Kharitonov grid of
//    the plan evaluates 15625 quartics per design point).

#include <benchmark/benchmark.h>

#include <complex>
#include <cstdint>
#include <vector>

#include "servotwin/core/norms.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace {

using namespace servotwin::core;

/// Sum of r_i w_i^2 / (s^2 + 2 z_i w_i s + w_i^2) in modal form (the "ten_state" system of
/// tools/reference/core_control_reference.py).
StateSpace ten_state_modal() {
  const double modes[5][3] = {{40.0, 0.01, 1.0}, {95.0, 0.015, -0.6}, {170.0, 0.01, 0.4}, {260.0, 0.02, 0.3}, {410.0, 0.012, -0.2}};
  StateSpace s{Eigen::MatrixXd::Zero(10, 10), Eigen::MatrixXd::Zero(10, 1), Eigen::MatrixXd::Zero(1, 10), Eigen::MatrixXd::Zero(1, 1)};
  for (int i = 0; i < 5; ++i) {
    const double w = modes[i][0], z = modes[i][1], r = modes[i][2];
    s.A(2 * i, 2 * i + 1) = 1.0;
    s.A(2 * i + 1, 2 * i) = -w * w;
    s.A(2 * i + 1, 2 * i + 1) = -2.0 * z * w;
    s.B(2 * i + 1, 0) = w * w;
    s.C(0, 2 * i) = r;
  }
  return s;
}

void BM_HinfNormTenStates(benchmark::State& state) {
  const StateSpace sys = ten_state_modal();
  for (auto _ : state) {
    PeakResult r = hinf_norm(sys);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_HinfNormTenStates)->Unit(benchmark::kMicrosecond);

void BM_PeakOnGrid4thOrder2000(benchmark::State& state) {
  // Antiresonance (zeta 0.05 at 30 rad/s) and resonance (zeta 0.02 at 60 rad/s) of a two-mass
  // drive with a zero at -5 and real poles at -0.5 and -80: (s^2 + 3 s + 900)(s + 5) /
  // ((s^2 + 2.4 s + 3600)(s + 80)(s + 0.5)).
  const TransferFunction g(Polynomial{1.0, 3.0, 900.0} * Polynomial{1.0, 5.0},
                           Polynomial{1.0, 2.4, 3600.0} * Polynomial{1.0, 80.0} * Polynomial{1.0, 0.5});
  const std::vector<double> grid = log_space(1e-1, 1e4, 2000);
  const auto f = [&](double w) { return g.frequency_response(w); };
  for (auto _ : state) {
    PeakResult r = peak_on_grid(f, grid);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(grid.size()));
}
BENCHMARK(BM_PeakOnGrid4thOrder2000)->Unit(benchmark::kMicrosecond);

void BM_RouthDegree6(benchmark::State& state) {
  // (s^2 + 0.2 s + 4)(s^2 + 1.5 s + 9)(s + 1)(s + 3): Hurwitz, so the full array is built.
  const Polynomial p = Polynomial{1.0, 0.2, 4.0} * Polynomial{1.0, 1.5, 9.0} * Polynomial{1.0, 4.0, 3.0};
  for (auto _ : state) {
    bool h = is_hurwitz(p);
    benchmark::DoNotOptimize(h);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RouthDegree6);

}  // namespace
