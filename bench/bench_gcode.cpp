// G-code readers and writers on large programs.
// Target: >= 1 M lines/s for both readers (items/s = lines) on one core; writers reported alongside.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>

#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/identification_program.hpp"

namespace {

using namespace servotwin::motion;

constexpr std::size_t kLines = 200'000;

/// A 200k-line identification program (two axes, 3-decimal targets), as the thesis would run.
Program big_identification(Dialect dialect) {
  IdentificationOptions o = identification_defaults(IdentificationSet::Standard);
  o.axes = {Axis::X, Axis::Y};
  o.moves = kLines;
  o.dialect = dialect;
  return make_identification_program(o);
}

/// A 200k-line ISO contour program mixing lines, arcs by I/J and by R, comments and M codes.
std::string contour_iso() {
  std::string text = "G21 G90 G17 G01 X0 Y0 F2000\n";
  for (std::size_t i = 1; i < kLines; i += 4) {
    const std::string n = std::to_string(i * 10);
    text += "N" + n + " G01 X10.000 Y0.000 F3000 (edge)\n";
    text += "N" + n + "1 G03 X10.000 Y10.000 I0.000 J5.000\n";
    text += "N" + n + "2 G02 X0.000 Y10.000 R5.000 M8\n";
    text += "N" + n + "3 G01 X0.000 Y0.000\n";
  }
  return text;
}

std::size_t count_lines(const std::string& text) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')); }

void BM_ParseIsoIdentification(benchmark::State& state) {
  const std::string text = write_iso(big_identification(Dialect::Iso));
  const std::size_t lines = count_lines(text);
  for (auto _ : state) benchmark::DoNotOptimize(parse_iso(text, "bench.nc"));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
}
BENCHMARK(BM_ParseIsoIdentification)->Unit(benchmark::kMillisecond);

void BM_ParseIsoContour(benchmark::State& state) {
  const std::string text = contour_iso();
  const std::size_t lines = count_lines(text);
  for (auto _ : state) benchmark::DoNotOptimize(parse_iso(text, "bench.nc"));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
}
BENCHMARK(BM_ParseIsoContour)->Unit(benchmark::kMillisecond);

void BM_ParseHeidenhain(benchmark::State& state) {
  const std::string text = write_heidenhain(big_identification(Dialect::Heidenhain));
  const std::size_t lines = count_lines(text);
  for (auto _ : state) benchmark::DoNotOptimize(parse_heidenhain(text, "bench.h"));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
}
BENCHMARK(BM_ParseHeidenhain)->Unit(benchmark::kMillisecond);

void BM_WriteIso(benchmark::State& state) {
  const Program p = big_identification(Dialect::Iso);
  std::size_t lines = 0;
  for (auto _ : state) {
    const std::string text = write_iso(p);
    lines = count_lines(text);
    benchmark::DoNotOptimize(text.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines));
}
BENCHMARK(BM_WriteIso)->Unit(benchmark::kMillisecond);

void BM_WriteHeidenhain(benchmark::State& state) {
  const Program p = big_identification(Dialect::Heidenhain);
  std::size_t lines = 0;
  for (auto _ : state) {
    const std::string text = write_heidenhain(p);
    lines = count_lines(text);
    benchmark::DoNotOptimize(text.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines));
}
BENCHMARK(BM_WriteHeidenhain)->Unit(benchmark::kMillisecond);

void BM_GenerateIdentification(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(big_identification(Dialect::Iso));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kLines));
}
BENCHMARK(BM_GenerateIdentification)->Unit(benchmark::kMillisecond);

}  // namespace
