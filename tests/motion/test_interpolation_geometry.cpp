// Geometry of the interpolated path (arc planes and directions, full circles, helices, spirals,
// tangent transitions), exact stops, axis selection, unit invariance and input validation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "motion/interpolation_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace interpolation_geometry_test {

using interp_test::norm;
using interp_test::ProgramBuilder;
using interp_test::sub;

constexpr double kPi = std::numbers::pi;

Point mid_position(const MotionPlan& plan) { return plan.position_at(0.5 * plan.duration()); }

TEST(InterpolationGeometry, ArcDirectionsFollowIsoPlanes) {
  // Quarter arcs turning the positive way (CCW) in each plane: first axis -> second axis.
  struct Case {
    Plane plane;
    std::size_t first, second;
  };
  for (const Case c : {Case{Plane::XY, 0, 1}, Case{Plane::ZX, 2, 0}, Case{Plane::YZ, 1, 2}}) {
    Point start{};
    start[c.first] = 10.0;
    Point end{};
    end[c.second] = 10.0;
    for (const bool ccw : {true, false}) {
      ProgramBuilder b(start);
      b.arc(ccw, c.plane, end, {0.0, 0.0, 0.0}, 6000.0);
      const MotionPlan plan = plan_motion(b.program(), InterpolationLimits{});
      ASSERT_EQ(plan.moves().size(), 1U);
      // CCW: the quarter through the first quadrant; CW: three quarters through the others.
      const double expected_len = (ccw ? 0.5 : 1.5) * kPi * 10.0;
      EXPECT_NEAR(plan.moves()[0].length, expected_len, 1e-12 * expected_len);
      const Point m = mid_position(plan);
      if (ccw) {
        EXPECT_GT(m[c.first], 0.0);
        EXPECT_GT(m[c.second], 0.0);
      } else {
        // Middle of the 270-degree CW arc from +first to +second is at -first... -second side.
        EXPECT_LT(m[c.first], 0.0);
        EXPECT_LT(m[c.second], 0.0);
      }
    }
  }
}

TEST(InterpolationGeometry, FullCircleAndHelix) {
  InterpolationLimits lim;
  {
    ProgramBuilder b({15.0, 5.0, 1.0});
    b.arc(false, Plane::XY, {15.0, 5.0, 1.0}, {10.0, 5.0, 0.0}, 6000.0);
    const MotionPlan plan = plan_motion(b.program(), lim);
    EXPECT_NEAR(plan.moves()[0].length, 2 * kPi * 5.0, 1e-12);
    // CW from angle 0: a quarter of the way round it is at angle -90 deg.
    const Trajectory tr = sample(plan, {Axis::X, Axis::Y, Axis::Z});
    double min_y = 1e9;
    for (std::size_t k = 0; k < tr.size(); ++k) min_y = std::min(min_y, tr.positions[1][k]);
    EXPECT_NEAR(min_y, 0.0, 1e-3);
    EXPECT_EQ(tr.positions[0].back(), 15.0);
    EXPECT_EQ(tr.positions[1].back(), 5.0);
  }
  {
    // One helical turn rising 6 mm: length sqrt((2 pi R)^2 + 6^2), Z linear in the angle.
    ProgramBuilder b({5.0, 0.0, 0.0});
    b.arc(true, Plane::XY, {5.0, 0.0, 6.0}, {0.0, 0.0, 0.0}, 3000.0);
    const MotionPlan plan = plan_motion(b.program(), lim);
    const double len = std::hypot(2 * kPi * 5.0, 6.0);
    EXPECT_NEAR(plan.moves()[0].length, len, 1e-12 * len);
    const Trajectory tr = sample(plan);
    ASSERT_EQ(tr.axes.size(), 3U);
    for (std::size_t k = 0; k < tr.size(); ++k) {
      const double angle = std::atan2(tr.positions[1][k], tr.positions[0][k]);
      const double turn = angle < 0 ? angle + 2 * kPi : angle;
      const double z = tr.positions[2][k];
      EXPECT_NEAR(std::hypot(tr.positions[0][k], tr.positions[1][k]), 5.0, 5e-9);
      if (z > 0.01 && z < 5.99) {
        EXPECT_NEAR(z, 6.0 * turn / (2 * kPi), 1e-9);
      }
    }
    EXPECT_EQ(tr.positions[2].back(), 6.0);
  }
}

TEST(InterpolationGeometry, ArcSamplingMatchesLibmToPicometres) {
  // The sampler evaluates cos/sin by angle addition from refreshed reference angles; the plan's
  // position_at uses std::cos/std::sin directly. Over several full turns of large circles and a
  // helix the two agree to 1e-12 mm (positions up to 100 mm), in both profile modes.
  ProgramBuilder b({100.0, 0.0, 0.0});
  b.arc(true, Plane::XY, {100.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 12000.0)
      .arc(false, Plane::XY, {100.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 6000.0)
      .arc(true, Plane::XY, {100.0, 0.0, 30.0}, {0.0, 0.0, 0.0}, 12000.0)
      .arc(true, Plane::YZ, {100.0, 0.0, 30.0}, {0.0, 50.0, 30.0}, 9000.0);
  for (const bool jerk : {false, true}) {
    InterpolationLimits lim;
    if (jerk) lim.jerk = 2e5;
    const MotionPlan plan = plan_motion(b.program(), lim);
    const Trajectory tr = sample(plan, {Axis::X, Axis::Y, Axis::Z});
    double worst = 0.0;
    for (std::size_t k = 0; k < tr.size(); ++k) {
      const Point p = plan.position_at(static_cast<double>(k) * tr.ts);
      for (std::size_t c = 0; c < kAxisCount; ++c) worst = std::max(worst, std::abs(tr.positions[c][k] - p[c]));
    }
    EXPECT_LT(worst, 1e-12) << (jerk ? "S-curve" : "trapezoid");
    EXPECT_GT(tr.size(), 5000U);
  }
}

TEST(InterpolationGeometry, SampleIntoReusesAndMatchesSample) {
  ProgramBuilder b;
  b.line({10.0, 0, 0}, 6000.0).arc(true, Plane::XY, {20.0, 0, 0}, {15.0, 0, 0}, 6000.0);
  const MotionPlan plan = plan_motion(b.program(), InterpolationLimits{});
  const Trajectory fresh = sample(plan);
  Trajectory reused;
  sample_into(plan, reused);
  const double* data = reused.positions[0].data();
  sample_into(plan, reused);  // second call into the same memory
  EXPECT_EQ(reused.positions[0].data(), data);
  EXPECT_EQ(reused.axes, fresh.axes);
  EXPECT_EQ(reused.positions, fresh.positions);
  EXPECT_EQ(reused.ts, fresh.ts);
}

TEST(InterpolationGeometry, SpiralReachesItsEndPoint) {
  // End radius 0.1 % larger than the start radius (readers accept such arcs): the radius grows
  // linearly with the angle and the end point is reached exactly.
  ProgramBuilder b({10.0, 0.0, 0.0});
  b.arc(true, Plane::XY, {0.0, 10.01, 0.0}, {0.0, 0.0, 0.0}, 6000.0);
  const MotionPlan plan = plan_motion(b.program(), InterpolationLimits{});
  const Trajectory tr = sample(plan);
  double prev = 0.0;
  for (std::size_t k = 0; k < tr.size(); ++k) {
    const double r = std::hypot(tr.positions[0][k], tr.positions[1][k]);
    const double angle = std::atan2(tr.positions[1][k], tr.positions[0][k]);
    EXPECT_GE(angle, prev - 1e-12);
    prev = angle;
    EXPECT_NEAR(r, 10.0 + 0.01 * angle / (kPi / 2), 1e-9);
  }
  EXPECT_EQ(tr.positions[0].back(), 0.0);
  EXPECT_EQ(tr.positions[1].back(), 10.01);
}

TEST(InterpolationGeometry, TangentTransitionsKeepSpeed) {
  // Line -> tangent arc -> tangent arc of opposite curvature -> tangent line: the speed never
  // drops to zero inside the chain (no exact stop), in both profile modes.
  ProgramBuilder b({-20.0, 0.0, 0.0});
  b.line({0.0, 0.0, 0.0}, 12000.0)
      .arc(true, Plane::XY, {10.0, 10.0, 0.0}, {0.0, 10.0, 0.0}, 12000.0)
      .arc(false, Plane::XY, {15.0, 15.0, 0.0}, {15.0, 10.0, 0.0}, 12000.0)
      .line({40.0, 15.0, 0.0}, 12000.0);
  for (const bool jerk : {false, true}) {
    InterpolationLimits lim;
    if (jerk) lim.jerk = 1e5;
    const MotionPlan plan = plan_motion(b.program(), lim);
    ASSERT_EQ(plan.moves().size(), 4U);
    for (std::size_t i = 0; i + 1 < 4; ++i) {
      EXPECT_FALSE(plan.moves()[i].stop_at_end);
      EXPECT_GT(plan.moves()[i].v_end, 1.0);
    }
    const Trajectory tr = sample(plan);
    for (std::size_t k = 1; k + 1 < tr.size(); ++k) {
      const double v = std::hypot(tr.positions[0][k + 1] - tr.positions[0][k], tr.positions[1][k + 1] - tr.positions[1][k]);
      EXPECT_GT(v, 0.0) << "sample " << k;
    }
    const interp_test::FdResult fd = interp_test::check_limits(b.program(), lim, plan, sample(plan, {Axis::X, Axis::Y, Axis::Z}));
    EXPECT_LE(fd.accel_ratio, 1.0);
    EXPECT_LE(fd.jerk_ratio, 1.0);
    // The line -> arc junction: the arc's speed limit sqrt(sqrt(1 - r^2) accel R) (R = 10,
    // r = 0.5) is the binding limit of the arc, so the junction runs at it (up to time scaling).
    if (!jerk) {
      EXPECT_NEAR(plan.moves()[0].v_end, std::sqrt(std::sqrt(0.75) * 2000.0 * 10.0), 2.0);
    }
  }
}

TEST(InterpolationGeometry, SharpCornerIsAnExactStopOnASample) {
  ProgramBuilder b({0.1, 0.2, 0.3});
  b.line({10.123456789, 0.2, 0.3}, 6000.0).line({10.123456789, 7.77, 0.3}, 6000.0);
  const MotionPlan plan = plan_motion(b.program(), InterpolationLimits{});
  ASSERT_EQ(plan.moves().size(), 2U);
  EXPECT_TRUE(plan.moves()[0].stop_at_end);
  EXPECT_EQ(plan.moves()[0].v_end, 0.0);
  const Trajectory tr = sample(plan, {Axis::X, Axis::Y, Axis::Z});
  interp_test::expect_exact_stops(b.program(), plan, tr);
  // Corner angle 90 deg is below a 120 deg corner angle: then the corner is passed with a
  // (small) junction speed instead.
  InterpolationLimits wide;
  wide.corner_angle_deg = 120.0;
  const MotionPlan plan2 = plan_motion(b.program(), wide);
  EXPECT_FALSE(plan2.moves()[0].stop_at_end);
  EXPECT_GT(plan2.moves()[0].v_end, 0.0);
  EXPECT_LT(plan2.moves()[0].v_end, 0.5 * 2000.0 * 0.001 / std::sqrt(2.0) + 1e-12);
}

TEST(InterpolationGeometry, ZeroLengthNoneAndEmptyPrograms) {
  Program empty;
  empty.start = {1.0, 2.0, 3.0};
  const MotionPlan p0 = plan_motion(empty, InterpolationLimits{});
  EXPECT_EQ(p0.sample_count(), 1U);
  const Trajectory t0 = sample(p0);
  ASSERT_EQ(t0.axes, std::vector<Axis>{Axis::X});
  EXPECT_EQ(t0.positions[0][0], 1.0);

  ProgramBuilder b;
  b.none().line({0, 0, 0}, 1000.0).line({5, 0, 0}, 6000.0).none().line({5, 0, 0}, 6000.0);
  ProgramBuilder ref;
  ref.line({5, 0, 0}, 6000.0);
  const MotionPlan p1 = plan_motion(b.program(), InterpolationLimits{});
  EXPECT_EQ(p1.sample_count(), plan_motion(ref.program(), InterpolationLimits{}).sample_count());
  ASSERT_EQ(p1.moves().size(), 1U);
  EXPECT_EQ(p1.moves()[0].block, 2U);
}

TEST(InterpolationGeometry, AxisSelection) {
  ProgramBuilder b;
  b.line({0.0, 3.0, 4.0}, 6000.0);
  const MotionPlan plan = plan_motion(b.program(), InterpolationLimits{});
  EXPECT_EQ(sample(plan).axes, (std::vector<Axis>{Axis::Y, Axis::Z}));
  const Trajectory tr = sample(plan, {Axis::Z, Axis::X});
  EXPECT_EQ(tr.axes, (std::vector<Axis>{Axis::X, Axis::Z}));
  EXPECT_EQ(tr.positions[0].back(), 0.0);
  EXPECT_EQ(tr.positions[1].back(), 4.0);
  EXPECT_THROW((void)sample(plan, {Axis::X, Axis::X}), core::InputError);
}

TEST(InterpolationGeometry, ResultsDoNotDependOnUnits) {
  // The same program in mm and in m (coordinates, feeds, accel, jerk scaled by 1e-3): the same
  // number of samples and the same positions up to the scale factor.
  interp_test::Rng rng(9);
  ProgramBuilder mm({1.0, 2.0, 0.0});
  ProgramBuilder m({1e-3, 2e-3, 0.0});
  Point p{1.0, 2.0, 0.0};
  for (int i = 0; i < 20; ++i) {
    const Point q{p[0] + rng.uniform(-5, 5), p[1] + rng.uniform(-5, 5), 0.0};
    const double f = rng.uniform(1000, 10000);
    if (i % 3 == 2) {
      const Point c{0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.0};
      mm.arc(true, Plane::XY, q, c, f);
      m.arc(true, Plane::XY, interp_test::mul(q, 1e-3), interp_test::mul(c, 1e-3), f * 1e-3);
    } else {
      mm.line(q, f);
      m.line(interp_test::mul(q, 1e-3), f * 1e-3);
    }
    p = q;
  }
  for (const bool jerk : {false, true}) {
    InterpolationLimits lmm;
    InterpolationLimits lm;
    lm.accel = lmm.accel * 1e-3;
    lm.rapid_feed_mm_min = lmm.rapid_feed_mm_min * 1e-3;
    lm.max_feed_mm_min = lmm.max_feed_mm_min * 1e-3;
    if (jerk) {
      lmm.jerk = 5e4;
      lm.jerk = 50.0;
    }
    const Trajectory a = interpolate(mm.program(), lmm);
    const Trajectory b = interpolate(m.program(), lm);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t c = 0; c < a.positions.size(); ++c)
      for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(b.positions[c][k] * 1e3, a.positions[c][k], 1e-9);
  }
}

// ---- validation ----

template <class F>
core::InputError expect_input_error(F&& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no core::InputError";
  return core::InputError("none");
}

TEST(InterpolationValidation, LimitsNameTheirField) {
  ProgramBuilder b;
  b.line({1, 0, 0}, 1000.0);
  const auto field_of = [&](auto change) {
    InterpolationLimits lim;
    change(lim);
    return expect_input_error([&] { (void)plan_motion(b.program(), lim); }).where().field;
  };
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.ts = 0.0; }), "ts");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.ts = std::nan(""); }), "ts");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.accel = -1.0; }), "accel");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.jerk = 0.0; }), "jerk");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.rapid_feed_mm_min = 0.0; }), "rapid_feed_mm_min");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.max_feed_mm_min = 0.0; }), "max_feed_mm_min");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.corner_angle_deg = 181.0; }), "corner_angle_deg");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.corner_angle_deg = -1.0; }), "corner_angle_deg");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.arc_tangential_ratio = 1.0; }), "arc_tangential_ratio");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.arc_tangential_ratio = 0.0; }), "arc_tangential_ratio");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.junction_share = 1.0; }), "junction_share");
  EXPECT_EQ(field_of([](InterpolationLimits& l) { l.max_samples = 0; }), "max_samples");
}

TEST(InterpolationValidation, BlocksNameTheirLine) {
  {
    ProgramBuilder b;
    b.line({1, 0, 0}, 1000.0).line({2, 0, 0}, 0.0);
    Program p = b.program();
    p.blocks[1].line = 12;
    const auto e = expect_input_error([&] { (void)plan_motion(p, InterpolationLimits{}); });
    EXPECT_EQ(e.where().line, 12U);
    EXPECT_NE(std::string(e.what()).find("line 12: feed must be > 0"), std::string::npos) << e.what();
  }
  {
    ProgramBuilder b;
    b.line({1, 0, 0}, 1000.0).line({2, 0, 0}, 1000.0);
    Program p = b.program();
    p.blocks[1].start = {1.5, 0, 0};  // does not start where the previous block ended
    EXPECT_EQ(expect_input_error([&] { (void)plan_motion(p, InterpolationLimits{}); }).where().line, 2U);
  }
  {
    ProgramBuilder b;
    b.arc(true, Plane::XY, {1, 1, 0}, {0, 0, 0}, 1000.0);  // starts on its centre
    EXPECT_EQ(expect_input_error([&] { (void)plan_motion(b.program(), InterpolationLimits{}); }).where().line, 1U);
  }
  {
    ProgramBuilder b;
    b.line({1, 0, 0}, 1000.0).dwell(-1.0);
    EXPECT_EQ(expect_input_error([&] { (void)plan_motion(b.program(), InterpolationLimits{}); }).where().line, 2U);
  }
  {
    ProgramBuilder b;
    b.line({1, std::nan(""), 0}, 1000.0);
    EXPECT_EQ(expect_input_error([&] { (void)plan_motion(b.program(), InterpolationLimits{}); }).where().line, 1U);
  }
}

TEST(InterpolationValidation, AbsurdSizesAreRejected) {
  ProgramBuilder b;
  b.line({1e6, 0, 0}, 1.0);  // 1000 km at 1 mm/min: 1.9 years
  EXPECT_EQ(expect_input_error([&] { (void)plan_motion(b.program(), InterpolationLimits{}); }).where().field, "max_samples");
  ProgramBuilder d;
  d.dwell(1e30);
  EXPECT_THROW((void)plan_motion(d.program(), InterpolationLimits{}), core::InputError);
  ProgramBuilder ok;
  ok.line({10, 0, 0}, 6000.0);
  InterpolationLimits tiny;
  tiny.max_samples = 10;
  EXPECT_THROW((void)plan_motion(ok.program(), tiny), core::InputError);
}

}  // namespace interpolation_geometry_test
}  // namespace
}  // namespace servotwin::motion
