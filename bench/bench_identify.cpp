// `servotwin identify` end to end on the measured EMPS capture (24 841 samples at 1 kHz, about
// 25 s): read the CSV, build the regressors and statistics, solve the bounded problem exactly and
// score the model by simulation.
//
// Target (Release, one core): <= 50 ms for a 22 s, 1 kHz capture, CSV reading included, with the
// default command-shift search (7 identifications). bench/reference/compare_identify.sh runs the
// same pipeline in numpy/scipy (bench/reference/identify_reference.py, fixed shift, no simulation)
// and prints the ratio to BM_IdentifyEmps/fixed_shift.
//
// BM_IdentifyEmpsRefined adds the output-error refinement (rapid/refine.hpp): a Levenberg-Marquardt
// search whose every step simulates the model on the whole capture (8 simulations per Jacobian).
// Target: <= 0.5 s on EMPS (the sliding-mode preset's capture, whose start model is faster than
// the sample rate and so takes the simulation's event path on every sample, needs about 1 s).

#include <benchmark/benchmark.h>

#include "servotwin/io/capture_csv.hpp"
#include "servotwin/vcnc/identification.hpp"

namespace {

using namespace servotwin;

vcnc::AxisIdentification identify_emps(bool search_shift, bool refine = false) {
  io::CaptureReadOptions o;
  o.map = {{"x_cmd", "qg"}, {"x_act", "qm"}};
  o.scale = 1000.0;
  std::vector<vcnc::NamedCapture> captures{{"emps", io::read_capture_file(SERVOTWIN_REPO_DATA_DIR "/emps/DATA_EMPS.csv", o)}};
  vcnc::IdentificationSettings settings;
  if (search_shift) settings.shift_search = vcnc::ShiftSearch{};
  settings.refine = refine;
  return vcnc::identify_axis(captures, {}, "x", settings);
}

void BM_IdentifyEmps(benchmark::State& state) {
  const bool search = state.range(0) != 0;
  for (auto _ : state) {
    const vcnc::AxisIdentification r = identify_emps(search);
    benchmark::DoNotOptimize(r.fit->nrmse);
  }
  state.SetItemsProcessed(state.iterations() * 24841);
  state.SetLabel(search ? "shift searched -3..3" : "fixed shift 0");
}
BENCHMARK(BM_IdentifyEmps)->ArgName("search_shift")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_IdentifyEmpsRefined(benchmark::State& state) {
  int simulations = 0;
  for (auto _ : state) {
    const vcnc::AxisIdentification r = identify_emps(false, true);
    simulations = r.refinement->simulations;
    benchmark::DoNotOptimize(r.fit->nrmse);
  }
  state.counters["simulations"] = simulations;
  state.SetLabel("fixed shift 0, exact + output-error refinement");
}
BENCHMARK(BM_IdentifyEmpsRefined)->Unit(benchmark::kMillisecond);

}  // namespace
