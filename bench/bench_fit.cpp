// Plant fit kernels. Target (task brief): a 40-point two-mass fit (starts + LM + covariance +
// physical parameters) in < 5 ms on one core. Items = fits.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>

#include "servotwin/fit/fit.hpp"

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

}  // namespace
