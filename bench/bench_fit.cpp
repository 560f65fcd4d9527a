// Plant fit kernels. Target (task brief): a 40-point two-mass fit (starts + LM + covariance +
// physical parameters) in < 5 ms on one core. Items = fits. The fit with Coulomb friction is timed
// with the linear fit it starts from, which runs alone beside it as the reference.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>

#include "servotwin/fit/fit.hpp"
#include "servotwin/fit/friction_fit.hpp"

namespace {

using namespace servotwin;

core::FrequencyResponse two_mass_response(std::size_t count, double noise) {
  fit::PlantModel m;
  m.gain = 0.5;
  m.rigid_pole_rad_s = 0.2;
  m.modes = {fit::Mode{{1.0, 0.06}, {3.0, 0.15}}};  // catalog E10 / Table 5.1 plant
  std::mt19937_64 rng(42);
  std::normal_distribution<double> n(0.0, 1.0);
  core::FrequencyResponse r;
  for (double w : core::log_space(0.05, 15.0, count)) {
    core::FrequencyPoint p;
    p.freq_hz = w / (2.0 * std::numbers::pi);
    p.value = m.response(w) * std::complex<double>(1.0 + noise * n(rng), noise * n(rng));
    r.points.push_back(p);
  }
  return r;
}

void BM_TwoMassFit40Points(benchmark::State& state) {
  const core::FrequencyResponse r = two_mass_response(40, 0.01 * static_cast<double>(state.range(0)));
  fit::FitOptions o;
  o.output = fit::OutputChoice::kVelocity;
  for (auto _ : state) {
    fit::FitReport report = fit::fit_plant(r, {}, o);
    benchmark::DoNotOptimize(report);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TwoMassFit40Points)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);  // noise-free, 1 % noise

void BM_AutoOrder40Points(benchmark::State& state) {
  const core::FrequencyResponse r = two_mass_response(40, 0.01);
  fit::FitOptions o;
  o.output = fit::OutputChoice::kVelocity;
  const fit::ModelRequest automatic{fit::ModelRequest::Kind::kAuto, 0};
  for (auto _ : state) {
    fit::FitReport report = fit::fit_plant(r, automatic, o);
    benchmark::DoNotOptimize(report);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AutoOrder40Points)->Unit(benchmark::kMillisecond);

/// A swept-sine response of the motor bench's chain (53/76 Hz, 0.2 ms current loop) as
/// `frf measure` gives it: 33 points from 1 to 500 Hz, each with its excitation amplitude, 1 %
/// noise, seen from the motor or the load.
core::FrequencyResponse bench_sweep(fit::SensorSide sensor) {
  fit::PlantModel actuator;
  actuator.lag_pole_rad_s = 5000.0;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 0.01);
  core::FrequencyResponse r;
  r.quality_kind = core::QualityKind::kThd;
  for (double f : core::log_space(1.0, 500.0, 33)) {
    const double w = 2.0 * std::numbers::pi * f;
    core::FrequencyPoint p;
    p.freq_hz = f;
    const auto response = sensor == fit::SensorSide::kMotor ? fit::coulomb_two_mass_response : fit::coulomb_two_mass_load_response;
    p.value = response(w, 1.0, 0.0048146, 0.0050854, 563.95, 0.06774, 3e-4, 0.0, 0.0, actuator) *
              std::complex<double>(1.0 + n(rng), n(rng));
    p.amplitude = 1.12;
    r.points.push_back(p);
  }
  return r;
}

/// `fit --lag` (Arg 0), then `--friction` on it (Arg 1: the time of both, the linear fit being the
/// reference in the same run), on the motor side (second Arg 0) or the load side (1).
void BM_FrictionFit33Points(benchmark::State& state) {
  const auto sensor = state.range(1) ? fit::SensorSide::kLoad : fit::SensorSide::kMotor;
  const core::FrequencyResponse r = bench_sweep(sensor);
  fit::FitOptions o;
  o.lag = true;
  o.sensor = sensor;
  for (auto _ : state) {
    fit::FitReport linear = fit::fit_plant(r, {}, o);
    if (state.range(0)) {
      fit::CoulombFit friction = fit::fit_coulomb_friction(r, linear, o);
      benchmark::DoNotOptimize(friction);
    }
    benchmark::DoNotOptimize(linear);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FrictionFit33Points)->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})->Unit(benchmark::kMillisecond);

/// The three-mass chain of the tuning study (38/69 and 271/320 Hz, 0.3 ms current loop) as `frf
/// measure` gives it from the motor: 36 points, 1 % noise. `fit --model modes:2 --lag` (Arg 0), then
/// `--friction` on it (Arg 1: a chain of three masses, its linear fit the reference in the same run).
void BM_FrictionFitThreeMass36Points(benchmark::State& state) {
  fit::PlantModel actuator;
  actuator.lag_pole_rad_s = 1.0 / 3e-4;
  std::mt19937_64 rng(8);
  std::normal_distribution<double> n(0.0, 0.01);
  core::FrequencyResponse r;
  r.quality_kind = core::QualityKind::kThd;
  for (double f : core::log_space(1.0, 500.0, 36)) {
    core::FrequencyPoint p;
    p.freq_hz = f;
    p.value = fit::coulomb_chain_response(2.0 * std::numbers::pi * f, 1.0, {2e-3, 1e-3, 6e-3}, {2500.0, 400.0}, {0.02, 0.01},
                                          0.0, 0.0, 0.0, actuator, fit::SensorSide::kMotor) *
              std::complex<double>(1.0 + n(rng), n(rng));
    p.amplitude = 0.5;
    r.points.push_back(p);
  }
  fit::FitOptions o;
  o.lag = true;
  const fit::ModelRequest two_modes{fit::ModelRequest::Kind::kModes, 2};
  for (auto _ : state) {
    fit::FitReport linear = fit::fit_plant(r, two_modes, o);
    if (state.range(0)) {
      fit::CoulombFit friction = fit::fit_coulomb_friction(r, linear, o);
      benchmark::DoNotOptimize(friction);
    }
    benchmark::DoNotOptimize(linear);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FrictionFitThreeMass36Points)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
