// Offline frequency-response estimation (frf/offline.hpp) and the recorded-signal reader.
//
// Targets (Release build, one core of the 2-core reference machine):
//  * H1 (Welch, Hann, 50 % overlap) on 1 M samples: < 100 ms, i.e. >= 10 M samples/s, for both a
//    4096-sample segment and the default segment (the largest power of two with >= 8 segments);
//    scipy 1.10 signal.csd + welch + coherence take about 0.3 s for the same job on this machine;
//  * multisine estimation on the 50 000-sample FdiTools recording (20 periods of 2500): < 5 ms
//    (>= 10 M samples/s);
//  * reading that recording's two columns from CSV: >= 2 M rows/s.
// items/s = samples (rows) processed per second.

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "servotwin/frf/offline.hpp"
#include "servotwin/io/signal_csv.hpp"

namespace {

using namespace servotwin;

struct Record {
  std::vector<double> x, y;
};

/// White noise through a 3-tap FIR plus output noise (seeded).
const Record& noise_record() {
  static const Record r = [] {
    std::mt19937_64 rng(17);
    std::normal_distribution<double> gauss;
    Record out;
    const std::size_t n = 1'000'000;
    out.x.resize(n);
    out.y.resize(n);
    for (auto& v : out.x) v = gauss(rng);
    for (std::size_t i = 0; i < n; ++i)
      out.y[i] = 0.5 * out.x[i] + (i > 0 ? 0.3 * out.x[i - 1] : 0.0) + (i > 1 ? 0.2 * out.x[i - 2] : 0.0) +
                 0.1 * gauss(rng);
    return out;
  }();
  return r;
}

const std::string kFdiTools = std::string(SERVOTWIN_REPO_DATA_DIR) + "/twomass-motor-bench-fditools/MultisineTypeA.csv";

io::SignalTable read_fditools() {
  io::SignalReadOptions o;
  o.columns = {"iq_adx", "theta_mx"};
  return io::read_signal_file(kFdiTools, o);
}

void BM_H1_1M(benchmark::State& state) {
  const Record& r = noise_record();
  frf::WelchOptions o;
  o.segment_length = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    auto h = frf::estimate_h1(r.x, r.y, 1e-3, o);
    benchmark::DoNotOptimize(h.points.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(r.x.size()));
}
BENCHMARK(BM_H1_1M)->Arg(4096)->Arg(0)->Unit(benchmark::kMillisecond);

void BM_MultisineFdiTools(benchmark::State& state) {
  const io::SignalTable t = read_fditools();
  const auto& x = t.column("iq_adx");
  const auto& y = t.column("theta_mx");
  frf::MultisineOptions o;
  o.periods = 20;
  o.skip_periods = 1;
  for (auto _ : state) {
    auto e = frf::estimate_multisine(x, y, t.ts, o);
    benchmark::DoNotOptimize(e.response.points.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(x.size()));
}
BENCHMARK(BM_MultisineFdiTools)->Unit(benchmark::kMillisecond);

void BM_ReadSignalCsvFdiTools(benchmark::State& state) {
  std::size_t rows = 0;
  for (auto _ : state) {
    const io::SignalTable t = read_fditools();
    rows = t.size();
    benchmark::DoNotOptimize(t.columns.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rows));
}
BENCHMARK(BM_ReadSignalCsvFdiTools)->Unit(benchmark::kMillisecond);

}  // namespace
