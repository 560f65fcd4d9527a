#pragma once
// Helpers of the interpolation tests: a program builder, a portable seeded generator and the
// finite-difference checker of speed, acceleration and jerk.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "servotwin/motion/interpolation.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::motion::interp_test {

/// Builds programs block by block; every block starts where the previous one ended.
class ProgramBuilder {
 public:
  explicit ProgramBuilder(Point start = {}) : cur_(start) { prog_.start = start; }

  ProgramBuilder& line(const Point& end, double feed_mm_min) { return push(BlockType::Linear, end, {}, Plane::XY, feed_mm_min); }
  ProgramBuilder& rapid(const Point& end) { return push(BlockType::Rapid, end, {}, Plane::XY, 0.0); }
  ProgramBuilder& arc(bool ccw, Plane plane, const Point& end, const Point& center, double feed_mm_min) {
    return push(ccw ? BlockType::ArcCcw : BlockType::ArcCw, end, center, plane, feed_mm_min);
  }
  ProgramBuilder& dwell(double seconds) {
    Block b;
    b.type = BlockType::Dwell;
    b.start = b.end = cur_;
    b.dwell_s = seconds;
    b.line = prog_.blocks.size() + 1;
    prog_.blocks.push_back(b);
    return *this;
  }
  ProgramBuilder& none() {
    Block b;
    b.type = BlockType::None;
    b.start = b.end = cur_;
    b.line = prog_.blocks.size() + 1;
    prog_.blocks.push_back(b);
    return *this;
  }
  [[nodiscard]] const Point& current() const { return cur_; }
  [[nodiscard]] const Program& program() const { return prog_; }

 private:
  ProgramBuilder& push(BlockType type, const Point& end, const Point& center, Plane plane, double feed) {
    Block b;
    b.type = type;
    b.start = cur_;
    b.end = end;
    b.center = center;
    b.plane = plane;
    b.feed_mm_min = feed;
    b.line = prog_.blocks.size() + 1;
    for (std::size_t i = 0; i < kAxisCount; ++i)
      if (end[i] != cur_[i]) b.axes = static_cast<std::uint8_t>(b.axes | axis_bit(static_cast<Axis>(i)));
    prog_.blocks.push_back(b);
    cur_ = end;
    return *this;
  }
  Program prog_;
  Point cur_;
};

/// Uniform doubles from a 64-bit Mersenne twister without std distributions (whose output is
/// implementation defined), so seeded tests draw the same programs on every platform.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : gen_(seed) {}
  double uniform() { return static_cast<double>(gen_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  std::size_t index(std::size_t n) { return std::min(n - 1, static_cast<std::size_t>(uniform() * static_cast<double>(n))); }
  bool chance(double p) { return uniform() < p; }

 private:
  std::mt19937_64 gen_;
};

inline Point add(const Point& a, const Point& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Point sub(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Point mul(const Point& a, double k) { return {a[0] * k, a[1] * k, a[2] * k}; }
inline double dot(const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const Point& a) { return std::sqrt(dot(a, a)); }

/// Feed limit of a block [mm/s] as the program and the limits define it.
inline double block_feed(const Block& b, const InterpolationLimits& lim) {
  if (b.type == BlockType::Rapid) return lim.rapid_feed_mm_min / 60.0;
  return std::min(b.feed_mm_min, lim.max_feed_mm_min) / 60.0;
}

/// Largest ratios of the finite differences to their limits, over the whole trajectory.
struct FdResult {
  double speed_ratio = 0.0;   ///< max |dx| / ts / (feed limit + tolerance)
  double accel_ratio = 0.0;   ///< max |d2x| / ts^2 / (accel + tolerance)
  double jerk_ratio = 0.0;    ///< max |d3x| / ts^3 / (jerk + tolerance)
  std::size_t worst_accel_sample = 0;
  std::size_t worst_jerk_sample = 0;
};

/// Checks by finite differences of the sampled positions (all three axes) that no sample
/// exceeds the feed of the blocks it overlaps, the acceleration limit and (if set) the jerk
/// limit. Tolerance, for floating point only: the positions are exact to
/// delta = 16 eps X (X = largest coordinate or block length), so a k-th difference / ts^k is
/// exact to 2^k delta / ts^k; the limits get a relative slack of 1e-9 for the rounding of the
/// planner's root finding and time scaling.
inline FdResult check_limits(const Program& program, const InterpolationLimits& lim, const MotionPlan& plan,
                             const Trajectory& tr) {
  FdResult r;
  const std::size_t n = tr.size();
  const double ts = tr.ts;
  double scale = 1e-300;
  for (const auto& col : tr.positions)
    for (const double x : col) scale = std::max(scale, std::abs(x));
  for (const PlannedMove& m : plan.moves()) scale = std::max(scale, m.length);
  const double delta = 16.0 * std::numeric_limits<double>::epsilon() * scale;
  const std::size_t dims = tr.positions.size();
  const auto diff = [&](std::size_t k, int order) {
    // |order-th difference starting at sample k| (vector norm over the axes)
    double sq = 0.0;
    for (std::size_t c = 0; c < dims; ++c) {
      const auto& x = tr.positions[c];
      double d = 0.0;
      if (order == 1) d = x[k + 1] - x[k];
      if (order == 2) d = x[k + 2] - 2.0 * x[k + 1] + x[k];
      if (order == 3) d = x[k + 3] - 3.0 * x[k + 2] + 3.0 * x[k + 1] - x[k];
      sq += d * d;
    }
    return std::sqrt(sq);
  };
  // Speed: the first difference over [t_k, t_k+1] is the mean velocity there, so it must stay
  // within the largest feed of the blocks overlapping that interval.
  const auto& moves = plan.moves();
  std::size_t mi = 0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double t0 = static_cast<double>(k) * ts;
    const double t1 = static_cast<double>(k + 1) * ts;
    while (mi < moves.size() && moves[mi].t_end <= t0) ++mi;
    double feed = 0.0;
    for (std::size_t j = mi; j < moves.size() && moves[j].t_start < t1; ++j)
      if (moves[j].type != BlockType::Dwell) feed = std::max(feed, block_feed(program.blocks[moves[j].block], lim));
    const double allowed = feed * (1.0 + 1e-9) + 2.0 * delta / ts;
    r.speed_ratio = std::max(r.speed_ratio, diff(k, 1) / ts / allowed);
  }
  const double a_allowed = lim.accel * (1.0 + 1e-9) + 4.0 * delta / (ts * ts);
  for (std::size_t k = 0; k + 2 < n; ++k) {
    const double ratio = diff(k, 2) / (ts * ts) / a_allowed;
    if (ratio > r.accel_ratio) {
      r.accel_ratio = ratio;
      r.worst_accel_sample = k + 1;
    }
  }
  if (lim.jerk) {
    const double j_allowed = *lim.jerk * (1.0 + 1e-9) + 8.0 * delta / (ts * ts * ts);
    for (std::size_t k = 0; k + 3 < n; ++k) {
      const double ratio = diff(k, 3) / (ts * ts * ts) / j_allowed;
      if (ratio > r.jerk_ratio) {
        r.jerk_ratio = ratio;
        r.worst_jerk_sample = k + 1;
      }
    }
  }
  return r;
}

/// Sample index of a time that must be a sample time (exact stops).
inline std::size_t sample_index(double t, double ts) { return static_cast<std::size_t>(std::llround(t / ts)); }

/// Expects every exact-stop point (and the program start) to be a sample equal bit for bit to the
/// programmed point.
inline void expect_exact_stops(const Program& program, const MotionPlan& plan, const Trajectory& tr) {
  ASSERT_EQ(tr.positions.size(), kAxisCount);
  for (std::size_t c = 0; c < kAxisCount; ++c) EXPECT_EQ(tr.positions[c].front(), program.start[c]);
  for (const PlannedMove& m : plan.moves()) {
    if (!m.stop_at_end) continue;
    const double k = m.t_end / tr.ts;
    ASSERT_NEAR(k, std::round(k), 1e-6) << "exact stop of line " << m.line << " is not on a sample";
    const std::size_t idx = sample_index(m.t_end, tr.ts);
    ASSERT_LT(idx, tr.size());
    const Block& b = program.blocks[m.block];
    for (std::size_t c = 0; c < kAxisCount; ++c)
      EXPECT_EQ(tr.positions[c][idx], b.end[c]) << "line " << m.line << " axis " << c << " sample " << idx;
  }
}

}  // namespace servotwin::motion::interp_test
