// `servotwin identify` end to end on the measured EMPS capture (24 841 samples at 1 kHz, about
// 25 s): read the CSV, build the regressors and statistics, solve the bounded problem exactly and
// score the model by simulation.
//
// Target (Release, one core): <= 50 ms for a 22 s, 1 kHz capture, CSV reading included, with the
// default command-shift search (7 identifications). bench/reference/compare_identify.sh runs the
// same pipeline in numpy/scipy (bench/reference/identify_reference.py, fixed shift, no simulation)
// and prints the ratio to BM_IdentifyEmps/fixed_shift.

#include <benchmark/benchmark.h>

#include "servotwin/io/capture_csv.hpp"
#include "servotwin/vcnc/identification.hpp"

namespace {

using namespace servotwin;

vcnc::AxisIdentification identify_emps(bool search_shift) {
  io::CaptureReadOptions o;
  o.map = {{"x_cmd", "qg"}, {"x_act", "qm"}};
  o.scale = 1000.0;
  std::vector<vcnc::NamedCapture> captures{{"emps", io::read_capture_file(SERVOTWIN_REPO_DATA_DIR "/emps/DATA_EMPS.csv", o)}};
  vcnc::IdentificationSettings settings;
  if (search_shift) settings.shift_search = vcnc::ShiftSearch{};
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

}  // namespace
