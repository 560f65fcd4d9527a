// Finite-difference checks of the sampled trajectories of many random programs: no sample
// exceeds the feed, the acceleration (vector, second differences) or the jerk (third
// differences, S-curve mode); every exact stop is a sample equal to the programmed point; the
// continuous profile passes through every continuous-feed junction; arcs stay on their circle.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <numbers>
#include <string>

#include "motion/interpolation_test_support.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace interpolation_limits_test {

using interp_test::add;
using interp_test::check_limits;
using interp_test::mul;
using interp_test::norm;
using interp_test::ProgramBuilder;
using interp_test::Rng;
using interp_test::sub;

constexpr double kPi = std::numbers::pi;

Point random_direction(Rng& rng, bool allow_3d) {
  const std::size_t axes = allow_3d ? 1 + rng.index(3) : 1;
  Point d{};
  for (;;) {
    d = {0.0, 0.0, 0.0};
    // Pick `axes` distinct axes.
    std::size_t placed = 0;
    while (placed < axes) {
      const std::size_t i = rng.index(3);
      if (d[i] != 0.0) continue;
      d[i] = rng.uniform(-1.0, 1.0);
      if (d[i] != 0.0) ++placed;
    }
    const double len = norm(d);
    if (len > 0.1) return mul(d, 1.0 / len);
  }
}

/// Random straight moves in 1-3 axes, random feeds, some rapids, some very short.
Program random_lines(Rng& rng) {
  ProgramBuilder b({rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-20, 20)});
  const std::size_t n = 20 + rng.index(30);
  for (std::size_t i = 0; i < n; ++i) {
    const Point end = add(b.current(), mul(random_direction(rng, true), rng.log_uniform(0.005, 40.0)));
    if (rng.chance(0.1))
      b.rapid(end);
    else
      b.line(end, rng.uniform(300.0, 15000.0));
  }
  return b.program();
}

/// Polylines that turn by small angles (shallow corners, many per sampling window when short).
Program shallow_polyline(Rng& rng, double corner_deg) {
  ProgramBuilder b({rng.uniform(-10, 10), rng.uniform(-10, 10), 0.0});
  Point dir = random_direction(rng, true);
  const double feed = rng.uniform(1000.0, 15000.0);
  const double short_scale = rng.log_uniform(0.002, 1.0);
  const std::size_t n = 60 + rng.index(120);
  for (std::size_t i = 0; i < n; ++i) {
    // Rotate dir by a random small angle about a random axis perpendicular to it.
    Point axis = random_direction(rng, true);
    axis = sub(axis, mul(dir, interp_test::dot(axis, dir)));
    if (norm(axis) > 1e-3) {
      axis = mul(axis, 1.0 / norm(axis));
      const double angle = rng.uniform(0.0, 1.2 * corner_deg) * kPi / 180.0;
      dir = add(mul(dir, std::cos(angle)), mul(axis, std::sin(angle)));
      dir = mul(dir, 1.0 / norm(dir));
    }
    const double len = rng.chance(0.8) ? short_scale * rng.uniform(0.5, 2.0) : rng.uniform(1.0, 10.0);
    b.line(add(b.current(), mul(dir, len)), rng.chance(0.1) ? rng.uniform(600.0, 15000.0) : feed);
  }
  return b.program();
}

/// CAM-style output: a tilted ellipse approximated by very short chords (0.001 - 0.05 mm), so
/// that many shallow corners fall into one sampling window.
Program cam_polyline(Rng& rng) {
  const double a = rng.uniform(2.0, 20.0);
  const double b = a * rng.uniform(0.3, 1.0);
  const double chord = rng.log_uniform(0.001, 0.05);
  const double tilt = rng.uniform(0.0, 0.5);
  const std::size_t n = std::min<std::size_t>(3000, static_cast<std::size_t>(2.0 * kPi * a / chord));
  const auto at = [&](double u) {
    return Point{a * std::cos(u), b * std::sin(u) * std::cos(tilt), b * std::sin(u) * std::sin(tilt)};
  };
  ProgramBuilder pb(at(0.0));
  const double feed = rng.uniform(3000.0, 15000.0);
  for (std::size_t i = 1; i <= n; ++i) pb.line(at(static_cast<double>(i) * chord / a), feed);
  return pb.program();
}

/// Lines and arcs joined tangentially (line-arc, arc-arc with other radius or reversed
/// curvature, arc-line) in a random plane.
Program tangent_chain(Rng& rng) {
  const Plane plane = std::array<Plane, 3>{Plane::XY, Plane::ZX, Plane::YZ}[rng.index(3)];
  const std::array<std::size_t, 3> ax = plane == Plane::XY ? std::array<std::size_t, 3>{0, 1, 2}
                                       : plane == Plane::ZX ? std::array<std::size_t, 3>{2, 0, 1}
                                                            : std::array<std::size_t, 3>{1, 2, 0};
  const auto to_point = [&](double u, double v, double w) {
    Point p{};
    p[ax[0]] = u;
    p[ax[1]] = v;
    p[ax[2]] = w;
    return p;
  };
  double u = rng.uniform(-5, 5);
  double v = rng.uniform(-5, 5);
  const double w = rng.uniform(-5, 5);
  double heading = rng.uniform(-kPi, kPi);
  ProgramBuilder b(to_point(u, v, w));
  const double feed = rng.uniform(1500.0, 15000.0);
  const std::size_t n = 8 + rng.index(12);
  for (std::size_t i = 0; i < n; ++i) {
    if (rng.chance(0.35)) {
      const double len = rng.log_uniform(0.05, 20.0);
      u += len * std::cos(heading);
      v += len * std::sin(heading);
      b.line(to_point(u, v, w), feed);
    } else {
      const bool ccw = rng.chance(0.5);
      const double radius = rng.log_uniform(0.3, 30.0);
      const double sweep = rng.uniform(0.05, 1.9 * kPi);
      const double side = ccw ? 1.0 : -1.0;  // centre to the left for CCW
      const double cu = u - side * radius * std::sin(heading);
      const double cv = v + side * radius * std::cos(heading);
      const double a0 = std::atan2(v - cv, u - cu);
      const double a1 = a0 + side * sweep;
      u = cu + radius * std::cos(a1);
      v = cv + radius * std::sin(a1);
      heading += side * sweep;
      b.arc(ccw, plane, to_point(u, v, w), to_point(cu, cv, 0.0), rng.chance(0.2) ? feed * 0.5 : feed);
    }
  }
  return b.program();
}

/// Arcs in random planes (some helical, some full circles, some spirals with slightly different
/// end radius) joined by lines.
Program mixed_arcs(Rng& rng, bool spirals) {
  ProgramBuilder b({rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5)});
  const std::size_t n = 6 + rng.index(8);
  for (std::size_t i = 0; i < n; ++i) {
    if (rng.chance(0.3)) {
      b.line(add(b.current(), mul(random_direction(rng, true), rng.log_uniform(0.1, 10.0))), rng.uniform(600.0, 12000.0));
      continue;
    }
    const std::size_t pi = rng.index(3);
    const Plane plane = std::array<Plane, 3>{Plane::XY, Plane::ZX, Plane::YZ}[pi];
    const std::array<std::size_t, 3> ax = pi == 0 ? std::array<std::size_t, 3>{0, 1, 2}
                                          : pi == 1 ? std::array<std::size_t, 3>{2, 0, 1}
                                                    : std::array<std::size_t, 3>{1, 2, 0};
    const Point s = b.current();
    const double radius = rng.log_uniform(0.5, 25.0);
    const double a0 = rng.uniform(-kPi, kPi);
    Point center = s;
    center[ax[0]] = s[ax[0]] - radius * std::cos(a0);
    center[ax[1]] = s[ax[1]] - radius * std::sin(a0);
    const bool ccw = rng.chance(0.5);
    Point end = s;
    if (!rng.chance(0.15)) {  // else a full circle (end == start in the plane)
      const double a1 = a0 + (ccw ? 1.0 : -1.0) * rng.uniform(0.02, 2.0 * kPi - 0.02);
      const double r1 = spirals ? radius * (1.0 + rng.uniform(-0.002, 0.002)) : radius;
      end[ax[0]] = center[ax[0]] + r1 * std::cos(a1);
      end[ax[1]] = center[ax[1]] + r1 * std::sin(a1);
    }
    if (rng.chance(0.4)) end[ax[2]] += rng.uniform(-8.0, 8.0);  // helix
    b.arc(ccw, plane, end, center, rng.uniform(600.0, 12000.0));
  }
  return b.program();
}

/// Back-and-forth moves, same-direction continuations, dwells, zero-length moves, None blocks.
Program reversals_and_dwells(Rng& rng) {
  ProgramBuilder b({0.0, 0.0, 0.0});
  const std::size_t n = 20 + rng.index(20);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = rng.uniform();
    if (r < 0.1) {
      b.dwell(rng.uniform(0.0, 0.05));
    } else if (r < 0.15) {
      b.line(b.current(), 1000.0);  // zero length: skipped
    } else if (r < 0.2) {
      b.none();
    } else {
      Point end = b.current();
      end[0] = rng.uniform(-10.0, 10.0);
      if (rng.chance(0.3)) end[1] = rng.uniform(-10.0, 10.0);
      b.line(end, rng.uniform(1000.0, 15000.0));
    }
  }
  return b.program();
}

InterpolationLimits random_limits(Rng& rng, bool jerk) {
  InterpolationLimits lim;
  lim.ts = std::array<double, 3>{0.0005, 0.001, 0.002}[rng.index(3)];
  lim.accel = rng.log_uniform(200.0, 10000.0);
  if (jerk) lim.jerk = rng.log_uniform(1e4, 1e7);
  lim.rapid_feed_mm_min = rng.uniform(5000.0, 30000.0);
  lim.corner_angle_deg = std::array<double, 6>{0.5, 1.0, 3.0, 10.0, 45.0, 180.0}[rng.index(6)];
  lim.arc_tangential_ratio = rng.uniform(0.2, 0.8);
  lim.junction_share = rng.uniform(0.2, 0.8);
  lim.exact_stop_every_block = rng.chance(0.1);
  return lim;
}

struct Totals {
  double speed = 0.0;
  double accel = 0.0;
  double jerk = 0.0;
  std::size_t runs = 0;
  std::size_t samples = 0;
};

/// Runs one program with limits; checks limits, exact stops, continuous junctions.
void check_program(const Program& program, const InterpolationLimits& lim, const std::string& what, Totals& totals) {
  SCOPED_TRACE(what);
  const MotionPlan plan = plan_motion(program, lim);
  const Trajectory tr = sample(plan, {Axis::X, Axis::Y, Axis::Z});
  ASSERT_EQ(tr.size(), plan.sample_count());
  const interp_test::FdResult fd = check_limits(program, lim, plan, tr);
  EXPECT_LE(fd.speed_ratio, 1.0);
  EXPECT_LE(fd.accel_ratio, 1.0) << "at sample " << fd.worst_accel_sample;
  EXPECT_LE(fd.jerk_ratio, 1.0) << "at sample " << fd.worst_jerk_sample;
  interp_test::expect_exact_stops(program, plan, tr);
  // The last sample is the last programmed end point.
  for (std::size_t c = 0; c < kAxisCount; ++c) EXPECT_EQ(tr.positions[c].back(), plan.end_point()[c]);
  // The continuous profile passes through every continuous-feed junction: position_at(t_end)
  // equals the block's end point up to the rounding of the coordinates (1e-12 scale) and of the
  // time t_end itself (a few ulp of t, i.e. a path error of v * 64 eps * t).
  double scale = 1.0;
  for (const Block& blk : program.blocks)
    for (std::size_t c = 0; c < kAxisCount; ++c) scale = std::max(scale, std::abs(blk.end[c]));
  const double eps = std::numeric_limits<double>::epsilon();
  for (const PlannedMove& m : plan.moves()) {
    if (m.stop_at_end || m.type == BlockType::Dwell) continue;
    EXPECT_GT(m.v_end, 0.0) << "line " << m.line;
    const Point p = plan.position_at(m.t_end);
    const double tol = 1e-12 * scale + 64.0 * eps * m.t_end * m.v_end;
    EXPECT_LE(norm(sub(p, program.blocks[m.block].end)), tol) << "junction after line " << m.line;
  }
  totals.speed = std::max(totals.speed, fd.speed_ratio);
  totals.accel = std::max(totals.accel, fd.accel_ratio);
  totals.jerk = std::max(totals.jerk, fd.jerk_ratio);
  totals.runs += 1;
  totals.samples += tr.size();
}

/// Number of seeds per family: the default, or SERVOTWIN_INTERPOLATION_SEEDS for longer soak runs.
int seed_count(int default_seeds) {
  const char* env = std::getenv("SERVOTWIN_INTERPOLATION_SEEDS");
  const int n = env != nullptr ? std::atoi(env) : 0;
  return n > 0 ? n : default_seeds;
}

void run_family(const std::string& name, const std::function<Program(Rng&, const InterpolationLimits&)>& make,
                std::uint64_t seed0, int default_seeds, bool expect_tight = true) {
  const int seeds = seed_count(default_seeds);
  for (const bool jerk : {false, true}) {
    Totals totals;
    for (int s = 0; s < seeds; ++s) {
      Rng rng(seed0 + static_cast<std::uint64_t>(s));
      const InterpolationLimits lim = random_limits(rng, jerk);
      const Program program = make(rng, lim);
      check_program(program, lim, name + (jerk ? " S-curve" : " trapezoid") + " seed " + std::to_string(seed0 + s), totals);
    }
    // The check is meaningful only if the trajectories actually use the limits (not so on dense
    // polylines, where the junction budget binds).
    if (expect_tight) {
      EXPECT_GT(totals.speed, 0.9) << name;
      EXPECT_GT(totals.accel, 0.9) << name;
      if (jerk) {
        EXPECT_GT(totals.jerk, 0.5) << name;
      }
    }
    std::printf("[ %-20s %-9s] %zu programs, %zu samples, max ratios: speed %.6f accel %.6f jerk %.6f\n", name.c_str(),
                jerk ? "S-curve" : "trapezoid", totals.runs, totals.samples, totals.speed, totals.accel, totals.jerk);
  }
}

TEST(InterpolationLimits, RandomLines) {
  run_family("random lines", [](Rng& rng, const InterpolationLimits&) { return random_lines(rng); }, 1000000, 12);
}

TEST(InterpolationLimits, ShallowCornerPolylines) {
  run_family("shallow polylines",
             [](Rng& rng, const InterpolationLimits& lim) { return shallow_polyline(rng, lim.corner_angle_deg); }, 2000000, 12);
}

TEST(InterpolationLimits, CamPolylines) {
  run_family("CAM polylines", [](Rng& rng, const InterpolationLimits&) { return cam_polyline(rng); }, 7000000, 6, false);
}

TEST(InterpolationLimits, TangentLineArcChains) {
  run_family("tangent chains", [](Rng& rng, const InterpolationLimits&) { return tangent_chain(rng); }, 3000000, 12);
}

TEST(InterpolationLimits, ArcsHelicesFullCircles) {
  run_family("arcs and helices", [](Rng& rng, const InterpolationLimits&) { return mixed_arcs(rng, false); }, 4000000, 10);
}

TEST(InterpolationLimits, Spirals) {
  run_family("spirals", [](Rng& rng, const InterpolationLimits&) { return mixed_arcs(rng, true); }, 5000000, 8);
}

TEST(InterpolationLimits, ReversalsAndDwells) {
  run_family("reversals, dwells", [](Rng& rng, const InterpolationLimits&) { return reversals_and_dwells(rng); }, 6000000, 12);
}

TEST(InterpolationLimits, CheckerDetectsViolations) {
  // Negative control: the same trajectory checked against tighter limits than it was planned
  // with must fail, so the checks above can fail.
  Rng rng(77);
  const Program program = random_lines(rng);
  InterpolationLimits lim;
  lim.jerk = 1e5;
  const MotionPlan plan = plan_motion(program, lim);
  const Trajectory tr = sample(plan, {Axis::X, Axis::Y, Axis::Z});
  InterpolationLimits tighter = lim;
  tighter.accel *= 0.95;
  tighter.jerk = *lim.jerk * 0.95;
  tighter.max_feed_mm_min = 100.0;
  tighter.rapid_feed_mm_min = 100.0;
  const interp_test::FdResult fd = check_limits(program, tighter, plan, tr);
  EXPECT_GT(fd.accel_ratio, 1.0);
  EXPECT_GT(fd.jerk_ratio, 1.0);
  EXPECT_GT(fd.speed_ratio, 1.0);
}

TEST(InterpolationLimits, ArcSamplesStayOnTheCircle) {
  // Every sample inside an arc is at distance R from its centre (relative 1e-9).
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    Rng rng(100 + seed);
    const Program program = tangent_chain(rng);
    InterpolationLimits lim;
    if (seed % 2 == 1) lim.jerk = 2e5;
    const MotionPlan plan = plan_motion(program, lim);
    const Trajectory tr = sample(plan, {Axis::X, Axis::Y, Axis::Z});
    std::size_t checked = 0;
    for (const PlannedMove& m : plan.moves()) {
      const Block& blk = program.blocks[m.block];
      if (blk.type != BlockType::ArcCw && blk.type != BlockType::ArcCcw) continue;
      const std::array<std::size_t, 2> ax = blk.plane == Plane::XY   ? std::array<std::size_t, 2>{0, 1}
                                            : blk.plane == Plane::ZX ? std::array<std::size_t, 2>{2, 0}
                                                                     : std::array<std::size_t, 2>{1, 2};
      const double radius = std::hypot(blk.start[ax[0]] - blk.center[ax[0]], blk.start[ax[1]] - blk.center[ax[1]]);
      for (std::size_t k = 0; k < tr.size(); ++k) {
        const double t = static_cast<double>(k) * tr.ts;
        if (t < m.t_start + 1e-9 || t > m.t_end - 1e-9) continue;
        const double r = std::hypot(tr.positions[ax[0]][k] - blk.center[ax[0]], tr.positions[ax[1]][k] - blk.center[ax[1]]);
        EXPECT_NEAR(r, radius, 1e-9 * radius) << "seed " << seed << " line " << m.line << " sample " << k;
        ++checked;
      }
    }
    EXPECT_GT(checked, 0U);
  }
}

}  // namespace interpolation_limits_test
}  // namespace
}  // namespace servotwin::motion
