// Interpolation benchmarks.
//
// Target: sampling (MotionPlan -> Trajectory) >= 20 M samples/s on a long multi-block program of
// lines and arcs in three axes, for trapezoidal and S-curve profiles (items/s = samples/s).
// BM_Sample returns a fresh Trajectory (its time includes the page faults of touching new
// output memory, which depend on the OS and allocator); BM_SampleInto reuses the output memory
// and so measures the interpolation itself.
// plan_motion is timed too (items/s = blocks/s); it runs once per program, so it has no hard
// target beyond staying well below the sampling time of the same program.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "servotwin/motion/interpolation.hpp"

namespace {

using servotwin::motion::Axis;
using servotwin::motion::Block;
using servotwin::motion::BlockType;
using servotwin::motion::InterpolationLimits;
using servotwin::motion::Plane;
using servotwin::motion::Point;
using servotwin::motion::Program;

enum class Mix { LinesAndArcs, Lines, Arcs };

/// Deterministic uniform numbers in [0, 1) (64-bit LCG, top 53 bits).
struct Lcg {
  std::uint64_t state = 0x9E3779B97F4A7C15ULL;
  double next() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  }
};

/// A long contouring program: tangent chains of lines and arcs in XY with Z steps, helices and
/// 3-axis moves between them (all three axes move).
Program make_program(std::size_t blocks, Mix mix) {
  Program p;
  Lcg rng;
  Point cur{0.0, 0.0, 0.0};
  double heading = 0.0;
  const auto push = [&](BlockType type, const Point& end, const Point& center, double feed) {
    Block b;
    b.type = type;
    b.start = cur;
    b.end = end;
    b.center = center;
    b.plane = Plane::XY;
    b.feed_mm_min = feed;
    b.line = p.blocks.size() + 1;
    p.blocks.push_back(b);
    cur = end;
  };
  for (std::size_t i = 0; i < blocks; ++i) {
    const bool arc = mix == Mix::Arcs || (mix == Mix::LinesAndArcs && rng.next() < 0.5);
    const double feed = 3000.0 + 9000.0 * rng.next();
    if (!arc) {
      const double len = 2.0 + 20.0 * rng.next();
      const double dz = rng.next() < 0.2 ? 2.0 * rng.next() - 1.0 : 0.0;
      push(BlockType::Linear, {cur[0] + len * std::cos(heading), cur[1] + len * std::sin(heading), cur[2] + dz}, {}, feed);
      if (dz != 0.0) heading += 0.5;  // a corner after 3-axis moves
    } else {
      const bool ccw = rng.next() < 0.5;
      const double side = ccw ? 1.0 : -1.0;
      const double radius = 2.0 + 20.0 * rng.next();
      const double sweep = 0.3 + 2.5 * rng.next();
      const double cx = cur[0] - side * radius * std::sin(heading);
      const double cy = cur[1] + side * radius * std::cos(heading);
      const double a1 = std::atan2(cur[1] - cy, cur[0] - cx) + side * sweep;
      const double dz = rng.next() < 0.3 ? 2.0 : 0.0;  // helix
      push(ccw ? BlockType::ArcCcw : BlockType::ArcCw, {cx + radius * std::cos(a1), cy + radius * std::sin(a1), cur[2] + dz},
           {cx, cy, 0.0}, feed);
      heading += side * sweep;
    }
  }
  return p;
}

InterpolationLimits limits(bool jerk) {
  InterpolationLimits lim;
  lim.ts = 0.001;
  lim.accel = 2000.0;
  if (jerk) lim.jerk = 1e5;
  return lim;
}

void BM_Sample(benchmark::State& state, Mix mix, bool jerk) {
  const Program program = make_program(2000, mix);
  const auto plan = servotwin::motion::plan_motion(program, limits(jerk));
  const std::vector<Axis> axes{Axis::X, Axis::Y, Axis::Z};
  for (auto _ : state) {
    auto tr = servotwin::motion::sample(plan, axes);
    benchmark::DoNotOptimize(tr.positions.front().data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(plan.sample_count()));
  state.counters["samples"] = static_cast<double>(plan.sample_count());
}

/// Sampling into a reused trajectory: the interpolation itself, without the page faults of
/// fresh output memory.
void BM_SampleInto(benchmark::State& state, Mix mix, bool jerk) {
  const Program program = make_program(2000, mix);
  const auto plan = servotwin::motion::plan_motion(program, limits(jerk));
  const std::vector<Axis> axes{Axis::X, Axis::Y, Axis::Z};
  servotwin::motion::Trajectory tr;
  for (auto _ : state) {
    servotwin::motion::sample_into(plan, tr, axes);
    benchmark::DoNotOptimize(tr.positions.front().data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(plan.sample_count()));
}

/// Reference in the same run: only allocating and filling three fresh columns of the same size
/// (what any function returning a new trajectory must at least do). Where BM_Sample is close to
/// this, its time is the operating system's cost of fresh memory, not interpolation.
void BM_FreshColumnsBaseline(benchmark::State& state, Mix mix, bool jerk) {
  const Program program = make_program(2000, mix);
  const std::size_t n = servotwin::motion::plan_motion(program, limits(jerk)).sample_count();
  for (auto _ : state) {
    std::vector<std::vector<double>> cols(3);
    for (auto& c : cols) c.reserve(n);
    for (std::size_t k = 0; k < n; ++k)
      for (auto& c : cols) c.push_back(static_cast<double>(k));
    benchmark::DoNotOptimize(cols.front().data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(n));
}

void BM_Plan(benchmark::State& state, Mix mix, bool jerk) {
  const Program program = make_program(2000, mix);
  const InterpolationLimits lim = limits(jerk);
  for (auto _ : state) {
    auto plan = servotwin::motion::plan_motion(program, lim);
    benchmark::DoNotOptimize(plan.sample_count());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(program.blocks.size()));
}

BENCHMARK_CAPTURE(BM_Sample, mixed_trapezoid, Mix::LinesAndArcs, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Sample, mixed_scurve, Mix::LinesAndArcs, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Sample, lines_trapezoid, Mix::Lines, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Sample, arcs_scurve, Mix::Arcs, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SampleInto, mixed_trapezoid, Mix::LinesAndArcs, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SampleInto, mixed_scurve, Mix::LinesAndArcs, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SampleInto, arcs_scurve, Mix::Arcs, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FreshColumnsBaseline, mixed_trapezoid, Mix::LinesAndArcs, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FreshColumnsBaseline, arcs_scurve, Mix::Arcs, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Plan, mixed_trapezoid, Mix::LinesAndArcs, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Plan, mixed_scurve, Mix::LinesAndArcs, true)->Unit(benchmark::kMillisecond);

}  // namespace
