// Excitations for a drive's signal generator and reading their recordings back
// (frf/excitation_design.hpp, frf/excitation_recording.hpp).
//
// Each case runs beside its floor in the same process:
//  * BM_DesignMultisine/{iterations}: a 10 000-sample period with 2 000 lines; 0 iterations is
//    Schroeder's phases alone (one inverse FFT), the default 200 swapping iterations cost about
//    400 FFT pairs; target < 100 ms for the default (a one-off design, not a per-sample path);
//  * BM_AlignRecording: locating a 60 s multisine (8 kHz, 480 000 samples) in a 600 000-sample
//    recording, beside BM_EstimateAlignedMultisine (the per-period DFTs of the same recording,
//    the work that follows) — alignment should cost no more than a few estimations
//    (target < 150 ms, >= 4 M samples/s);
//  * BM_EstimateSineSteps: the single-line DFTs of 30 steps over 600 000 samples (target
//    >= 20 M samples/s).
// items/s = recording samples processed per second.

#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "servotwin/frf/excitation_design.hpp"
#include "servotwin/frf/excitation_recording.hpp"
#include "servotwin/frf/offline.hpp"

namespace {

using namespace servotwin;

struct Played {
  frf::Excitation excitation;
  std::vector<double> x, y;
};

/// The excitation with a lead-in of 60 000 samples and a tail, through a resonance, with noise.
Played play(frf::ExcitationType type, std::size_t periods) {
  frf::ExcitationRequest r;
  r.type = type;
  r.f_begin_hz = 2.0;
  r.f_end_hz = 1000.0;
  r.ts = 1.0 / 8000.0;
  r.duration_s = 60.0;
  r.amplitude = 1.0;
  r.periods = periods;
  Played p;
  p.excitation = frf::design_excitation(r);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-3);
  p.x.assign(60'000, 0.0);
  p.x.insert(p.x.end(), p.excitation.samples.begin(), p.excitation.samples.end());
  p.x.resize(p.x.size() + 60'000, 0.0);
  p.y.resize(p.x.size());
  double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  for (std::size_t n = 0; n < p.x.size(); ++n) {
    p.y[n] = 0.1 * p.x[n] + 0.05 * x1 + 0.02 * x2 + 1.6 * y1 - 0.9 * y2;
    x2 = x1;
    x1 = p.x[n];
    y2 = y1;
    y1 = p.y[n];
    p.y[n] += noise(rng);
  }
  return p;
}

const Played& multisine() {
  static const Played p = play(frf::ExcitationType::kMultisine, 30);
  return p;
}

void BM_DesignMultisine(benchmark::State& state) {
  frf::ExcitationRequest r;
  r.f_begin_hz = 1.0;
  r.f_end_hz = 2000.0;
  r.ts = 1e-4;  // period 10 000 samples, 2 000 lines
  r.duration_s = 3.0;
  r.amplitude = 1.0;
  r.crest_iterations = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(frf::design_excitation(r));
  state.counters["crest_factor"] = frf::design_excitation(r).crest_factor;
}
BENCHMARK(BM_DesignMultisine)->Arg(0)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_AlignRecording(benchmark::State& state) {
  const Played& p = multisine();
  for (auto _ : state) benchmark::DoNotOptimize(frf::align_excitation(p.x, p.excitation.samples));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.x.size()));
}
BENCHMARK(BM_AlignRecording)->Unit(benchmark::kMillisecond);

void BM_EstimateAlignedMultisine(benchmark::State& state) {
  const Played& p = multisine();
  frf::MultisineOptions o;
  o.period_samples = p.excitation.period_samples;
  o.periods = p.excitation.periods - 1;
  o.excited_lines = p.excitation.lines;
  const std::size_t start = 60'000 + p.excitation.period_samples;
  const std::size_t length = o.periods * o.period_samples;
  for (auto _ : state)
    benchmark::DoNotOptimize(frf::estimate_multisine(std::span(p.x).subspan(start, length),
                                                     std::span(p.y).subspan(start, length), p.excitation.ts, o));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * length));
}
BENCHMARK(BM_EstimateAlignedMultisine)->Unit(benchmark::kMillisecond);

void BM_EstimateSineSteps(benchmark::State& state) {
  static const Played p = [] {
    Played s = play(frf::ExcitationType::kSineSteps, 0);
    return s;
  }();
  for (auto _ : state)
    benchmark::DoNotOptimize(frf::estimate_sine_steps(p.x, p.y, p.excitation.ts, p.excitation.steps, 60'000));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * p.x.size()));
}
BENCHMARK(BM_EstimateSineSteps)->Unit(benchmark::kMillisecond);

}  // namespace
