// Minimum time of simple moves against closed forms (within one sample), rapid feed, feed cap,
// dwell, and the thesis's identification program (Table 3.2 kind: 200 random X moves within
// +-10 mm at F12000 with 2000 mm/s^2, trapezoidal; the thesis captured 22 s).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "motion/interpolation_test_support.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion {
namespace {

using interp_test::ProgramBuilder;
using interp_test::Rng;

/// Rest-to-rest minimum time with speed and acceleration limits (trapezoid or triangle).
double trapezoid_time(double len, double v, double a) {
  if (len >= v * v / a) return len / v + v / a;
  return 2.0 * std::sqrt(len / a);
}

/// Rest-to-rest minimum time with speed, acceleration and jerk limits and zero acceleration at
/// both ends (standard double-S closed form, e.g. Biagiotti & Melchiorri, "Trajectory Planning
/// for Automatic Machines and Robots", sec. 3.4, with zero boundary speeds).
double scurve_time(double len, double v, double a, double j) {
  // Time and distance to reach speed vp from rest.
  const auto accel_time = [&](double vp) { return vp * j >= a * a ? vp / a + a / j : 2.0 * std::sqrt(vp / j); };
  if (len >= v * accel_time(v)) return len / v + accel_time(v);  // cruise at v
  // No cruise: peak speed vp with len = vp * accel_time(vp).
  const double vp_full = a * a / j;  // smallest peak speed at which a is reached
  double vp = 0.0;
  if (len >= vp_full * accel_time(vp_full)) {
    // len = vp (vp / a + a / j)  ->  vp^2 / a + vp a / j - len = 0
    vp = 0.5 * a * (-a / j + std::sqrt(a * a / (j * j) + 4.0 * len / a));
  } else {
    // len = vp * 2 sqrt(vp / j)  ->  vp = (len^2 j / 4)^(1/3)
    vp = std::cbrt(len * len * j / 4.0);
  }
  return 2.0 * accel_time(vp);
}

/// Expects the plan to take ceil(t_min / ts) samples: at least the minimum, less than one
/// sample more.
void expect_min_time(const MotionPlan& plan, double t_min, const char* what) {
  const double ts = plan.ts();
  const double expected_periods = std::ceil(t_min / ts - 1e-9);
  EXPECT_EQ(static_cast<double>(plan.sample_count() - 1), expected_periods) << what << ": t_min = " << t_min;
  EXPECT_GE(plan.duration(), t_min - 1e-9) << what;
  EXPECT_LT(plan.duration(), t_min + ts) << what;
}

TEST(InterpolationTime, TrapezoidSingleLine) {
  InterpolationLimits lim;
  lim.accel = 2000.0;
  for (const double len : {0.37, 5.0, 19.7, 20.3, 123.4}) {
    for (const Point dir : {Point{1, 0, 0}, Point{0.6, -0.8, 0}, Point{2.0 / 7.0, 3.0 / 7.0, 6.0 / 7.0}}) {
      ProgramBuilder b({1.0, 2.0, 3.0});
      b.line(interp_test::add(b.current(), interp_test::mul(dir, len)), 12000.0);
      const MotionPlan plan = plan_motion(b.program(), lim);
      expect_min_time(plan, trapezoid_time(len, 200.0, 2000.0), "trapezoid");
    }
  }
}

TEST(InterpolationTime, SCurveSingleLineAllCases) {
  struct Case {
    double len, feed_mm_min, accel, jerk;
    const char* what;
  };
  // v = 200 mm/s, a = 2000, j = 20000 -> a^2/j = 200: accel limit reached exactly at v.
  const Case cases[] = {
      {100.0, 12000.0, 2000.0, 1e5, "feed and accel reached"},
      {100.0, 12000.0, 2000.0, 1e4, "feed reached, accel not (a^2/j > v)"},
      {8.0, 12000.0, 2000.0, 1e6, "accel reached, feed not"},
      {0.3, 12000.0, 2000.0, 1e5, "neither reached"},
      {2.0, 6000.0, 500.0, 3e4, "mixed"},
  };
  for (const Case& c : cases) {
    InterpolationLimits lim;
    lim.accel = c.accel;
    lim.jerk = c.jerk;
    ProgramBuilder b;
    b.line({c.len * 0.8, c.len * 0.6, 0.0}, c.feed_mm_min);
    const MotionPlan plan = plan_motion(b.program(), lim);
    expect_min_time(plan, scurve_time(c.len, c.feed_mm_min / 60.0, c.accel, c.jerk), c.what);
  }
}

TEST(InterpolationTime, CollinearBlocksActAsOneMove) {
  // Same direction, same feed: no stop at the junction, the time of one move of the total length.
  InterpolationLimits lim;
  ProgramBuilder b;
  b.line({3.0, 0, 0}, 9000.0).line({7.5, 0, 0}, 9000.0).line({40.0, 0, 0}, 9000.0);
  expect_min_time(plan_motion(b.program(), lim), trapezoid_time(40.0, 150.0, 2000.0), "collinear trapezoid");
  lim.jerk = 5e4;
  expect_min_time(plan_motion(b.program(), lim), scurve_time(40.0, 150.0, 2000.0, 5e4), "collinear S-curve");
}

TEST(InterpolationTime, RapidRunsAtRapidFeed) {
  InterpolationLimits lim;
  lim.rapid_feed_mm_min = 24000.0;  // 400 mm/s
  lim.max_feed_mm_min = 6000.0;     // caps programmed feeds only
  ProgramBuilder b;
  b.rapid({300.0, 0.0, 0.0});
  const MotionPlan plan = plan_motion(b.program(), lim);
  expect_min_time(plan, trapezoid_time(300.0, 400.0, 2000.0), "rapid");
  const Trajectory tr = sample(plan);
  double vmax = 0.0;
  for (std::size_t k = 0; k + 1 < tr.size(); ++k) vmax = std::max(vmax, (tr.positions[0][k + 1] - tr.positions[0][k]) / tr.ts);
  const double k_scale = plan.duration() / trapezoid_time(300.0, 400.0, 2000.0);  // time scaling onto samples
  EXPECT_NEAR(vmax, 400.0 / k_scale, 1e-6);
  EXPECT_LE(vmax, 400.0 * (1 + 1e-12));
}

TEST(InterpolationTime, MaxFeedCapsProgrammedFeed) {
  InterpolationLimits lim;
  lim.max_feed_mm_min = 3000.0;
  ProgramBuilder b;
  b.line({0.0, 100.0, 0.0}, 12000.0);
  expect_min_time(plan_motion(b.program(), lim), trapezoid_time(100.0, 50.0, 2000.0), "max feed");
}

TEST(InterpolationTime, DwellHoldsForWholeSamples) {
  InterpolationLimits lim;
  ProgramBuilder b;
  b.line({10.0, 0, 0}, 6000.0).dwell(0.2505).line({10.0, 5.0, 0}, 6000.0);
  const MotionPlan plan = plan_motion(b.program(), lim);
  const double t1 = trapezoid_time(10.0, 100.0, 2000.0);
  const double t2 = trapezoid_time(5.0, 100.0, 2000.0);
  const std::size_t n1 = static_cast<std::size_t>(std::ceil(t1 / lim.ts - 1e-9));
  const std::size_t n2 = static_cast<std::size_t>(std::ceil(t2 / lim.ts - 1e-9));
  const std::size_t nd = 251;  // ceil(0.2505 / 0.001)
  ASSERT_EQ(plan.sample_count(), 1 + n1 + nd + n2);
  const Trajectory tr = sample(plan);
  ASSERT_EQ(tr.axes.size(), 2U);
  for (std::size_t k = n1; k <= n1 + nd; ++k) {
    EXPECT_EQ(tr.positions[0][k], 10.0);
    EXPECT_EQ(tr.positions[1][k], 0.0);
  }
  EXPECT_GT(tr.positions[1][n1 + nd + 1], 0.0);
  ASSERT_EQ(plan.moves().size(), 3U);
  EXPECT_EQ(plan.moves()[1].type, BlockType::Dwell);
  EXPECT_NEAR(plan.moves()[1].t_end - plan.moves()[1].t_start, 0.251, 1e-12);
}

TEST(InterpolationTime, ThesisIdentificationProgram) {
  // Table 3.2 kind: G00 to the centre, 200 random G01 X moves uniformly within +-10 mm at F12000
  // (200 mm/s), accel 2000 mm/s^2, trapezoidal, ts = 1 ms; the thesis captured 22 s.
  Rng rng(32);
  ProgramBuilder b;
  std::vector<double> xs{0.0};
  for (int i = 0; i < 200; ++i) {
    const double x = std::round(rng.uniform(-10.0, 10.0) * 1000.0) / 1000.0;  // 3 decimals as in the table
    b.line({x, 0.0, 0.0}, 12000.0);
    xs.push_back(x);
  }
  b.line({0.0, 0.0, 0.0}, 12000.0);
  xs.push_back(0.0);
  InterpolationLimits lim;
  lim.accel = 2000.0;
  const MotionPlan plan = plan_motion(b.program(), lim);
  // Reference: reversals are exact stops, same-direction moves continue at the feed, so the
  // program is a sequence of rest-to-rest moves over the monotone runs; each takes
  // ceil(t_min / ts) samples.
  double periods = 0.0;
  double t_min_total = 0.0;
  std::size_t runs = 0;
  std::size_t i = 0;
  while (i + 1 < xs.size()) {
    if (xs[i + 1] == xs[i]) {
      ++i;
      continue;
    }
    const double sign = xs[i + 1] > xs[i] ? 1.0 : -1.0;
    std::size_t j = i + 1;
    while (j + 1 < xs.size() && (xs[j + 1] - xs[j]) * sign >= 0.0) ++j;
    const double t = trapezoid_time(std::abs(xs[j] - xs[i]), 200.0, 2000.0);
    t_min_total += t;
    periods += std::ceil(t / lim.ts - 1e-9);
    ++runs;
    i = j;
  }
  EXPECT_EQ(static_cast<double>(plan.sample_count() - 1), periods);
  // With an exact stop after every block (G61, a controller without look-ahead) every move is a
  // rest-to-rest move of its own.
  lim.exact_stop_every_block = true;
  const MotionPlan stop_plan = plan_motion(b.program(), lim);
  double stop_periods = 0.0;
  for (std::size_t k = 0; k + 1 < xs.size(); ++k)
    if (xs[k + 1] != xs[k]) stop_periods += std::ceil(trapezoid_time(std::abs(xs[k + 1] - xs[k]), 200.0, 2000.0) / lim.ts - 1e-9);
  EXPECT_EQ(static_cast<double>(stop_plan.sample_count() - 1), stop_periods);
  std::printf("[ thesis program ] continuous feed: %zu rest-to-rest runs, %.3f s (unrounded optimum %.3f s); "
              "exact stop every block: %.3f s; thesis capture: 22 s\n",
              runs, plan.duration(), t_min_total, stop_plan.duration());
  // Plausible against the thesis's 22 s capture: all moves here are shorter than v^2 / a = 20 mm,
  // so each is a triangle of 2 sqrt(d / a); E[sqrt(d)] for d = 20 |u1 - u2|, u uniform, is
  // sqrt(20) 8/15, so 200 moves stopping after each take about 200 * 2 * sqrt(20 / 2000) * 8/15
  // = 21.3 s; continuing through same-direction moves saves a few seconds.
  EXPECT_GT(stop_plan.duration(), 19.0);
  EXPECT_LT(stop_plan.duration(), 24.0);
  EXPECT_GT(plan.duration(), 14.0);
  EXPECT_LT(plan.duration(), stop_plan.duration());
}

TEST(InterpolationTime, DenseChordsOfACircleRunAtAPlausibleSpeed) {
  // A circle of radius 10 mm as 0.01 mm chords (0.057 deg corners). The jumps in a stretch of
  // 2 ts v (a second-difference window) sum to v (2 ts v / R), i.e. they act like a centripetal
  // acceleration 2 v^2 / R, kept within share * accel: the chords run at about
  // sqrt(share accel R / 2) = 70.7 mm/s (a little less for the accel term of the window length),
  // slower than the true circle (sqrt(sqrt(0.75) accel R) = 131.6 mm/s) but of the same order,
  // i.e. physically sane -- neither a stop at every chord nor the feed.
  ProgramBuilder b({10.0, 0.0, 0.0});
  const int n = 6283;
  for (int i = 1; i <= n; ++i) {
    const double u = 2.0 * std::numbers::pi * i / n;
    b.line({10.0 * std::cos(u), 10.0 * std::sin(u), 0.0}, 12000.0);
  }
  InterpolationLimits lim;
  const MotionPlan plan = plan_motion(b.program(), lim);
  const double v_mid = plan.speed_at(0.5 * plan.duration());
  std::printf("[ dense chords ] mid-circle speed %.2f mm/s, %.3f s for the circle\n", v_mid, plan.duration());
  EXPECT_GT(v_mid, 0.9 * std::sqrt(0.5 * 2000.0 * 10.0 / 2.0));
  EXPECT_LT(v_mid, std::sqrt(std::sqrt(0.75) * 2000.0 * 10.0));
}

TEST(InterpolationTime, ShallowCornerSpeedCap) {
  // Two long lines with a 0.5 deg corner (corner angle 1 deg): the junction speed is capped at
  // share accel ts / (2 sin(theta / 2)) (isolated junction: only its own jump in the window).
  InterpolationLimits lim;
  lim.accel = 2000.0;
  lim.junction_share = 0.5;
  const double theta = 0.5 * std::numbers::pi / 180.0;
  ProgramBuilder b;
  b.line({100.0, 0, 0}, 12000.0).line({200.0, 100.0 * std::tan(theta), 0}, 12000.0);
  const MotionPlan plan = plan_motion(b.program(), lim);
  const double cap = 0.5 * 2000.0 * 0.001 / (2.0 * std::sin(theta / 2.0));
  ASSERT_EQ(plan.moves().size(), 2U);
  EXPECT_FALSE(plan.moves()[0].stop_at_end);
  const double k = plan.moves()[0].v_end;
  EXPECT_LE(k, cap * (1 + 1e-12));
  EXPECT_GT(k, cap * 0.95);  // the time scaling onto samples slows down by less than one sample
  // With the jerk limit the third-difference budget caps it at share jerk ts^2 / (2 sin(theta/2)).
  lim.jerk = 1e5;
  const MotionPlan plan_j = plan_motion(b.program(), lim);
  const double cap_j = 0.5 * 1e5 * 1e-6 / (2.0 * std::sin(theta / 2.0));
  EXPECT_LE(plan_j.moves()[0].v_end, cap_j * (1 + 1e-12));
  EXPECT_GT(plan_j.moves()[0].v_end, cap_j * 0.95);
}

}  // namespace
}  // namespace servotwin::motion
