// PI/PID design times on a fitted two-mass plant with friction (issue 7, §9 of the issue).
// Target: a PI/PID design together with its robustness scan <= 10 ms in total, so the design
// part measured here (normalization, numeric pole placement, second pair, admissible range,
// advice) should stay well under 1 ms; a single pole placement is on the inner loop of every ω*
// scan and should take a few microseconds.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/hinf.hpp"
#include "servotwin/tuning/lqg.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"
#include "servotwin/tuning/robustness.hpp"
#include "servotwin/tuning/tune.hpp"

namespace {

using namespace servotwin;
using namespace servotwin::tuning;

/// A belt axis like the catalog's A5 (fz = 4.5 Hz, fn = 12.1 Hz) with friction, a second mode and
/// a lag, as a fit would return it.
fit::PlantModel belt_axis() {
  constexpr double two_pi = 6.283185307179586;
  fit::PlantModel m;
  m.gain = 180.0;
  m.rigid_pole_rad_s = 2.5;
  m.modes = {{{two_pi * 4.5, 0.03}, {two_pi * 12.1, 0.07}}, {{two_pi * 60.0, 0.02}, {two_pi * 85.0, 0.03}}};
  m.lag_pole_rad_s = 2500.0;
  return m;
}

void BM_PiPolePlacement(benchmark::State& state) {
  const core::TransferFunction plant = normalize(belt_axis()).motor(false);
  double omega_star = 0.5;
  for (auto _ : state) {
    benchmark::DoNotOptimize(pi_pole_placement(plant, omega_star, 0.8));
    omega_star += 1e-12;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PiPolePlacement);

void BM_SecondPair(benchmark::State& state) {
  const NormalizedPlant plant = normalize(belt_axis());
  const PiGains gains = pi_pole_placement(plant.motor(false), 0.5, 0.8).gains;
  for (auto _ : state) benchmark::DoNotOptimize(second_pair(plant, gains, 0.5, 0.8));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SecondPair);

void BM_AdmissibleRange(benchmark::State& state) {
  const NormalizedPlant plant = normalize(belt_axis());
  for (auto _ : state) benchmark::DoNotOptimize(admissible_range(plant, 0.8));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AdmissibleRange)->Unit(benchmark::kMicrosecond);

// The whole design step a `tune --structure pi` / `pid` call makes before its robustness scan.
void BM_PiDesignTotal(benchmark::State& state) {
  const fit::PlantModel model = belt_axis();
  for (auto _ : state) {
    const NormalizedPlant plant = normalize(model);
    const ResonanceRatioAdvice advice = advise(plant.r, 0.8);
    const AdmissibleRange range = admissible_range(plant, 0.8);
    const double omega_star = 0.9 * range.omega_max;
    const PolePlacement placed = pi_pole_placement(plant.motor(false), omega_star, 0.8);
    const SecondPair pair = second_pair(plant, placed.gains, omega_star, 0.8);
    const PidDesign pid = pid_design(plant, 2.0, omega_star, 0.8, default_derivative_time_constant(plant.r, omega_star));
    benchmark::DoNotOptimize(advice);
    benchmark::DoNotOptimize(to_physical(placed.gains, plant));
    benchmark::DoNotOptimize(pair);
    benchmark::DoNotOptimize(pid);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PiDesignTotal)->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------- robustness (C7.9, plan §1.7)
// Target: the whole robustness scan (Kharitonov, the 5⁶-point grid fallback, the largest robust
// ω* search) within the 10 ms PI budget. E28 boxes: "literal" (±10 %, ω ±30 %) makes Kharitonov
// fail so the grid runs; "w48" (ω ±48 %) makes the ω* search scan and bisect.

IntervalPlant e28_box(double omega_spread) {
  return make_interval_plant({1.0, 0.1, 0.02, 0.01, 2.0, 1.0}, {0.1, 0.1, 0.1, 0.1, omega_spread, 0.1});
}

void BM_Kharitonov(benchmark::State& state) {
  const IntervalPlant box = e28_box(0.3);
  const PiGains gains = nominal_pi_design(box, 0.9, 0.7071067811865476);
  for (auto _ : state) benchmark::DoNotOptimize(kharitonov(box, gains));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Kharitonov);

// Items: grid cases (15625 per call).
void BM_GridCheck5(benchmark::State& state) {
  const IntervalPlant box = e28_box(0.3);
  const PiGains gains = nominal_pi_design(box, 0.9, 0.7071067811865476);
  std::size_t cases = 0;
  for (auto _ : state) {
    const GridResult r = grid_check(box, gains, 5);
    cases += r.cases;
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(cases));
}
BENCHMARK(BM_GridCheck5)->Unit(benchmark::kMicrosecond);

void BM_LargestRobustOmegaStar(benchmark::State& state) {
  const IntervalPlant box = e28_box(static_cast<double>(state.range(0)) / 100.0);
  for (auto _ : state) benchmark::DoNotOptimize(largest_robust_omega_star(box, 0.7071067811865476));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LargestRobustOmegaStar)->Arg(30)->Arg(48)->Unit(benchmark::kMillisecond);

// The whole `servotwin tune` step (issue §9: a PI/PID design with its robustness scan <= 10 ms):
// normalization, advice, admissible range, the automatic ω* scan (24 candidates + refinement, each
// a placement, a Routh test, two peaks and a bandwidth with the HF dynamics), the final analysis
// (indices, margins, time responses). Arg 0: PI; 1: PI with an uncertainty weight (RP in the scan);
// 2: PID; 3: PI + P position loop; 4: LQG (kbw and kff searches, C7.13); 5: LQG with W2;
// 9: PI with notch:auto (issue 25 §5: the scan per candidate notch width, plus the design without;
// compare with Arg 0, the same PI without filters); 10: PI with a given notch and low-pass at 8 kHz
// (the placement on plant·F).
// 6: H∞ with the automatic ω0S/ω0T search (C7.14; issue §9: <= 1 s), on the belt axis's full two-mode
// model (C7.16 active, the default: a 12-state generalized plant); 7: the position LQG (lqg-pos,
// kbw search with a prefilter bisection per candidate); 8: the position H∞ (hinf-pos: cubic
// weights, 14-state generalized plant, and the prefilter).
void BM_TuneAutomatic(benchmark::State& state) {
  const fit::PlantModel model = belt_axis();
  TuneOptions o;
  o.ms = 2.0;
  o.mt = 2.0;
  const double wz = 6.283185307179586 * 4.5;
  switch (state.range(0)) {
    case 1:
      o.w2 = core::TransferFunction(core::Polynomial{0.5 / wz, 0.05}, core::Polynomial{1.0 / wz, 1.0});
      break;
    case 2:
      o.structure = Structure::kPid;
      break;
    case 3:
      o.structure = Structure::kPiP;
      break;
    case 4:  // lqg: the kbw search (36 designs + bisection) and the feedforward search
      o.structure = Structure::kLqg;
      break;
    case 5:  // lqg with W2: robust tracking in every candidate
      o.structure = Structure::kLqg;
      o.w2 = core::TransferFunction(core::Polynomial{0.5 / wz, 0.05}, core::Polynomial{1.0 / wz, 1.0});
      break;
    case 6:  // hinf: the w0S scan with the w0T ladder, each candidate a gamma iteration
      o.structure = Structure::kHinf;
      break;
    case 7:
      o.structure = Structure::kLqgPos;
      break;
    case 8:
      o.structure = Structure::kHinfPos;
      break;
    case 9:
      o.ts = 1.0 / 8000.0;
      o.auto_notch = true;
      break;
    case 10: {
      o.ts = 1.0 / 8000.0;
      DriveFilterSpec notch;
      notch.frequency_hz = 40.0;
      notch.width_hz = 12.0;
      notch.depth_db = 20.0;
      DriveFilterSpec low;
      low.type = DriveFilterType::kLowpass;
      low.frequency_hz = 600.0;
      o.drive_filters = {notch, low};
      break;
    }
    default:
      break;
  }
  for (auto _ : state) benchmark::DoNotOptimize(tune(model, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TuneAutomatic)->DenseRange(0, 10)->Unit(benchmark::kMillisecond);

/// The load-measuring designs of C7.17 on the belt axis's first mode alone (they need a two-mass
/// load): Arg 0 hinf-load (the w0S scan over its whole range: feasibility is not monotone on load
/// feedback), 1 lqg-load (kbw and feedforward searches on the two-measurement loop).
void BM_TuneLoadSide(benchmark::State& state) {
  fit::PlantModel model = belt_axis();
  model.modes.resize(1);
  TuneOptions o;
  o.ms = 2.0;
  o.mt = 2.0;
  o.structure = state.range(0) == 0 ? Structure::kHinfLoad : Structure::kLqgLoad;
  for (auto _ : state) benchmark::DoNotOptimize(tune(model, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TuneLoadSide)->DenseRange(0, 1)->Unit(benchmark::kMillisecond);

/// One C7.14 velocity design (generalized plant, gamma iteration to 1e-4 with the closed loop
/// checked near the optimum, K0/s): the inner step of the w0S search; a few milliseconds.
void BM_VelocityHinfDesign(benchmark::State& state) {
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  VelocityHinfWeights w;
  w.omega_0s = 0.6;
  for (auto _ : state) {
    benchmark::DoNotOptimize(velocity_hinf(plant, w));
    w.omega_0s += 1e-9;
  }
}
BENCHMARK(BM_VelocityHinfDesign)->Unit(benchmark::kMillisecond);

/// The C7.16 two-mode designs on the demo plant of eq. 7.165 (10-state generalized plant, the
/// controller's minimal realization by balanced truncation): Arg 0 passive, 1 active. The inner
/// step of the tuner's search on a two-mode plant; a few milliseconds.
void BM_TwoModeHinfDesign(benchmark::State& state) {
  NormalizedPlant plant = normalized_two_mass(4.0, 0.01, 0.04);
  plant.higher_modes.push_back(fit::Mode{{6.0, 0.01}, {12.0, 0.02}});
  VelocityHinfWeights w;
  w.omega_0s = 0.7;
  w.modes = state.range(0) == 0 ? ModeHandling::kPassive : ModeHandling::kActive;
  for (auto _ : state) {
    benchmark::DoNotOptimize(velocity_hinf(plant, w));
    w.omega_0s += 1e-9;
  }
  state.SetLabel(to_string(w.modes));
}
BENCHMARK(BM_TwoModeHinfDesign)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// One LQG design (two 4x4 or 5x5 Riccati solves, the compensator and every pole set): the inner
/// step of a kbw search, so it should stay well under a millisecond. Arg 2: velocity on the model
/// extended by two higher modes (C7.16: 8x8 and 8x8 Riccati solves).
void BM_LqgDesign(benchmark::State& state) {
  const bool position = state.range(0) == 1;
  const FrictionTwoMass plant{8.0, 8.0, 0.16, 0.01, 0.02};  // r = 3, zeta_z = 0.01 (E29) with friction
  std::vector<fit::Mode> modes;
  if (state.range(0) == 2) modes = {{{4.0, 0.02}, {6.0, 0.01}}, {{9.0, 0.01}, {14.0, 0.02}}};
  double kbw = 1.0;
  for (auto _ : state) {
    if (!modes.empty()) {
      VelocityLqgOptions o;
      o.kbw = kbw;
      benchmark::DoNotOptimize(velocity_lqg(plant, modes, 3.0, o));
    } else if (position) {
      PositionLqgOptions o;
      o.kbw = kbw;
      benchmark::DoNotOptimize(position_lqg(plant, 3.0, o));
    } else {
      VelocityLqgOptions o;
      o.kbw = kbw;
      benchmark::DoNotOptimize(velocity_lqg(plant, 3.0, o));
    }
    kbw += 1e-9;
  }
  state.SetLabel(!modes.empty() ? "velocity, 2 higher modes" : position ? "position" : "velocity");
}
BENCHMARK(BM_LqgDesign)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

}  // namespace
