// The shaper comparison report (`servotwin shaper compare --report`): building the document for the
// seven classic shapers of one mode (ZV, ZVD, ZVDD, MZV, EI, 2-hump EI, 3-hump EI at 40 Hz,
// zeta 0.1: comparison table with bands and max accel, 1001-point frequency curves, damping curves,
// impulses, step responses), and writing it as HTML.
//
// Targets (Release, one core): shaper_report <= 3 ms, write_html of it <= 5 ms (the command stays
// interactive). Items = shapers compared.

#include <benchmark/benchmark.h>

#include <numbers>
#include <sstream>

#include "servotwin/report/shaper_report.hpp"
#include "servotwin/shaping/families.hpp"

namespace {

using namespace servotwin;

std::vector<report::NamedShaper> classic_set() {
  std::vector<report::NamedShaper> set;
  for (const std::string& name : shaping::shaper_type_names()) {
    const shaping::ShaperType type = shaping::parse_shaper_type(name);
    if (type == shaping::ShaperType::kZv4) continue;
    set.push_back({name + ".json", shaping::design_shaper(type, 2.0 * std::numbers::pi * 40.0, 0.1)});
  }
  return set;
}

void BM_ShaperReport(benchmark::State& state) {
  const auto set = classic_set();
  for (auto _ : state) benchmark::DoNotOptimize(report::shaper_report(set));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(set.size()));
}
BENCHMARK(BM_ShaperReport)->Unit(benchmark::kMillisecond);

void BM_ShaperReportHtml(benchmark::State& state) {
  const report::Document doc = report::shaper_report(classic_set());
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::ostringstream out;
    report::write_html(out, doc);
    bytes = out.str().size();
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["bytes"] = static_cast<double>(bytes);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(report::chart_count(doc)));
}
BENCHMARK(BM_ShaperReportHtml)->Unit(benchmark::kMillisecond);

}  // namespace
