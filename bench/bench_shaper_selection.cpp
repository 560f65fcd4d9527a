// Automatic shaper selection on a real 160-row Klipper spectrum (data/klipper-ender5s1-psd,
// resonances_x: two separated peaks, so two-mode shapers are searched too).
// Target (issue 6 §4 / task): a full selection well under 100 ms. Items = selections.
#include <benchmark/benchmark.h>

#include <numbers>
#include <string>

#include "servotwin/io/klipper_csv.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/selection.hpp"

namespace {

using namespace servotwin;

shaping::Spectrum spectrum(const char* file) {
  return io::load_klipper_csv(std::string(SERVOTWIN_REPO_DATA_DIR) + "/" + file);
}

constexpr const char* kEnderX = "klipper-ender5s1-psd/resonances_x_20230321_171058.csv";

void BM_SelectFromSpectrum(benchmark::State& state) {
  const shaping::Spectrum s = spectrum(kEnderX);
  shaping::SpectrumSelectionOptions o;
  o.multi_mode = state.range(0) != 0;
  state.SetLabel(o.multi_mode ? "with two-mode search" : "single-mode families only");
  for (auto _ : state) benchmark::DoNotOptimize(shaping::select_shaper_from_spectrum(s, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SelectFromSpectrum)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_SelectUnderSmoothingLimit(benchmark::State& state) {
  // A smoothing limit lets the scan start at low frequencies: the widest vibration tables.
  const shaping::Spectrum s = spectrum(kEnderX);
  shaping::SpectrumSelectionOptions o;
  o.max_smoothing = 0.2;
  for (auto _ : state) benchmark::DoNotOptimize(shaping::select_shaper_from_spectrum(s, o));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SelectUnderSmoothingLimit)->Unit(benchmark::kMillisecond);

void BM_RemainingVibrationsExact(benchmark::State& state) {
  const shaping::PreparedSpectrum p = shaping::prepare_spectrum(spectrum(kEnderX));
  const shaping::Shaper sh = shaping::design_shaper(shaping::ShaperType::kThreeHumpEi, 2.0 * std::numbers::pi * 58.4, 0.1);
  for (auto _ : state) benchmark::DoNotOptimize(shaping::remaining_vibrations(sh, p));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RemainingVibrationsExact)->Unit(benchmark::kMicrosecond);

void BM_SelectFromModel(benchmark::State& state) {
  const std::vector<shaping::KnownMode> modes = {{18.0, 0.01}, {61.0, 0.03}};
  for (auto _ : state) benchmark::DoNotOptimize(shaping::select_shaper_from_model(modes));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SelectFromModel)->Unit(benchmark::kMicrosecond);

}  // namespace
