// Contour error geometry against closed forms (distance to a circle, to a line, to a corner
// point) and against a brute-force search over the densely sampled continuous path
// (MotionPlan::position_at, independent of the nearest-point code), for circles, lines, corners,
// helices and spirals.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/contour.hpp"
#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion {
namespace {

constexpr double kPi = std::numbers::pi;

InterpolationLimits limits() {
  InterpolationLimits l;
  l.ts = 0.001;
  l.accel = 2000.0;
  return l;
}

/// Time at which the commanded point is on block `block` halfway.
double mid_time(const MotionPlan& plan, std::size_t block) {
  for (const auto& m : plan.moves())
    if (m.block == block) return 0.5 * (m.t_start + m.t_end);
  ADD_FAILURE() << "no move for block " << block;
  return 0.0;
}

/// Time (on the sample grid) at which the commanded point is nearest to the circle's angle `angle`
/// about `center` while on block `block`.
double time_at_angle(const MotionPlan& plan, std::size_t block, const Point& center, double angle) {
  double best_t = 0.0, best = 1e9;
  for (const auto& m : plan.moves()) {
    if (m.block != block) continue;
    for (double t = m.t_start; t <= m.t_end; t += plan.ts()) {
      const Point q = plan.position_at(t);
      const double gap = std::abs(std::remainder(std::atan2(q[1] - center[1], q[0] - center[0]) - angle, 2.0 * kPi));
      if (gap < best) {
        best = gap;
        best_t = t;
      }
    }
  }
  return std::round(best_t / plan.ts()) * plan.ts();
}

TEST(Contour, CircleDistanceIsTheRadialOffsetPositiveInsideACounterClockwiseCircle) {
  ContourProgramOptions o;
  o.center = {5.0, -3.0, 1.0};
  o.size_mm = 40.0;
  const Program program = make_circle_program(o);
  const MotionPlan plan = plan_motion(program, limits());
  const ContourPath path(program, plan);
  ASSERT_EQ(path.segment_count(), 3u);  // rapid out, circle, rapid back
  // Angle 0 is where the rapids join the circle: inside points there lie on a rapid (skipped).
  for (int i = 1; i < 24; ++i) {
    const double angle = 2.0 * kPi * i / 24.0;
    // Where the command passes that angle: the window (+-0.05 s, +-9 mm of arc) holds that part.
    const double t = time_at_angle(plan, 1, o.center, angle);
    for (const double rho : {19.0, 19.99, 20.0, 20.5, 23.0}) {
      const Point p{5.0 + rho * std::cos(angle), -3.0 + rho * std::sin(angle), 1.0};
      const ContourPoint c = path.nearest(p, t, 0.05);
      EXPECT_NEAR(c.distance, std::abs(rho - 20.0), 1e-12) << angle << " " << rho;
      EXPECT_NEAR(c.signed_distance, 20.0 - rho, 1e-12);
      EXPECT_NEAR(std::hypot(c.nearest[0] - 5.0, c.nearest[1] + 3.0), 20.0, 1e-12);
    }
  }
  // A deviation along the plane normal adds in quadrature.
  const ContourPoint c = path.nearest({5.0 + 21.0 * std::cos(0.5), -3.0 + 21.0 * std::sin(0.5), 1.0 + 0.5},
                                      time_at_angle(plan, 1, o.center, 0.5), 0.05);
  EXPECT_NEAR(c.distance, std::hypot(1.0, 0.5), 1e-12);
  // Only the part of the circle run within the window counts: the far side is not "near".
  const double t = time_at_angle(plan, 1, o.center, 0.5 * kPi);
  const ContourPoint far = path.nearest({5.0, -3.0 - 20.5, 1.0}, t, 0.05);  // beside the circle at -90 deg
  EXPECT_GT(far.distance, 10.0);
}

TEST(Contour, SignIsContinuousAcrossTheRapidToArcJoin) {
  // An axis pair lagging 5 samples behind the command, 20 um down and left: around the rapid -> arc
  // join the lagging point is still near the rapid's end, below it (right of travel): the signed
  // error is its y (the distance to the rapid's line, negative). With whole segments in the
  // window, the circle's last part (arriving at the same point from below) was nearer than the
  // rapid for some of those samples and the signed error flipped to about +20 um: a 40 um spike.
  const Program program = make_circle_program({});
  const MotionPlan plan = plan_motion(program, limits());
  const ContourPath path(program, plan);
  const Trajectory c = sample(plan, {Axis::X, Axis::Y});
  std::vector<std::vector<double>> lagging(2, std::vector<double>(c.size()));
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::size_t j = k >= 5 ? k - 5 : 0;
    lagging[0][k] = c.positions[0][j] - 0.02;
    lagging[1][k] = c.positions[1][j] - 0.02;
  }
  const std::vector<double> e = contour_errors(path, c.axes, lagging);
  const double t_join = plan.moves()[0].t_end;
  std::size_t checked = 0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    // While the lagging point is beside the rapid's last millimetre (x in [19, 19.98]), below it.
    const double x = lagging[0][k];
    if (static_cast<double>(k) * plan.ts() > t_join + 0.05 || x < 19.0 || x > 19.98 || lagging[1][k] >= 0.0) continue;
    EXPECT_NEAR(e[k], lagging[1][k], 1e-12) << "sample " << k;
    ++checked;
  }
  EXPECT_GT(checked, 5u);
}

TEST(Contour, ErrorsAreTheSameForAnyNumberOfThreads) {
  // contour_errors shares the samples among threads; each sample's error depends on that sample
  // only, so one, two and three workers give the same numbers bit for bit.
  // Helical turns (arcs with a Z rise), diamonds and their corners, 30 times: about 40 s.
  std::string text = "G17 G90 G01 X20 Y0 Z0 F6000\n";
  for (int i = 1; i <= 30; ++i) {
    text += "G03 X20 Y0 Z" + std::to_string(-0.2 * i) + " I-20 J0\n";
    text += "G01 X0 Y20\nG01 X-20 Y0\nG01 X0 Y-20\nG01 X20 Y0\n";
  }
  const Program program = parse_iso(text, "helix.nc");
  const MotionPlan plan = plan_motion(program, limits());
  const ContourPath path(program, plan);
  const Trajectory c = sample(plan, {Axis::X, Axis::Y, Axis::Z});
  std::vector<std::vector<double>> lagging(3, std::vector<double>(c.size()));
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::size_t j = k >= 7 ? k - 7 : 0;
    lagging[0][k] = c.positions[0][j] + 0.01 * std::sin(0.01 * static_cast<double>(k));
    lagging[1][k] = c.positions[1][j];
    lagging[2][k] = c.positions[2][j];
  }
  ASSERT_GT(c.size(), 3 * 8192U);  // long enough for three parts
  const std::vector<double> one = contour_errors(path, c.axes, lagging, 1);
  EXPECT_EQ(contour_errors(path, c.axes, lagging, 2), one);
  EXPECT_EQ(contour_errors(path, c.axes, lagging, 3), one);
}

TEST(Contour, ClockwiseArcIsPositiveOutside) {
  const Program program = parse_iso("G17 G01 X10 Y0 F6000\nG02 X-10 Y0 I-10 J0\n", "cw.nc");
  const MotionPlan plan = plan_motion(program, limits());
  const ContourPath path(program, plan);
  const double t = mid_time(plan, 1);
  // The clockwise half circle from (10, 0) to (-10, 0) passes (0, -10); left of travel is outside.
  EXPECT_NEAR(path.nearest({0.0, -11.0, 0.0}, t, 0.01).signed_distance, 1.0, 1e-12);
  EXPECT_NEAR(path.nearest({0.0, -9.0, 0.0}, t, 0.01).signed_distance, -1.0, 1e-12);
  // Past the path's end (the arc ends at (-10, 0) heading +Y) the path continues along its end
  // tangent: 3 mm beyond the end on that line is no contour deviation; 1 mm to its left (outside)
  // is +1 mm.
  const double t_end = plan.duration();
  EXPECT_NEAR(path.nearest({-10.0, 3.0, 0.0}, t_end, 1.0).distance, 0.0, 1e-12);
  const ContourPoint beyond = path.nearest({-11.0, 3.0, 0.0}, t_end, 1.0);
  EXPECT_NEAR(beyond.signed_distance, 1.0, 1e-12);
  EXPECT_NEAR(beyond.nearest[1], 3.0, 1e-12);
}

TEST(Contour, DiamondEdgesAndCorners) {
  ContourProgramOptions o;
  o.size_mm = 40.0;
  const Program program = make_diamond_program(o);
  const MotionPlan plan = plan_motion(program, limits());
  const ContourPath path(program, plan);
  ASSERT_EQ(path.segment_count(), 6u);
  // First edge (20, 0) -> (0, 20): travel direction (-1, 1)/sqrt 2, left of it is the origin side.
  const double t1 = mid_time(plan, 1);
  const Point mid{10.0, 10.0, 0.0};
  const double d = 0.3;
  EXPECT_NEAR(path.nearest({mid[0] - d / std::sqrt(2.0), mid[1] - d / std::sqrt(2.0), 0.0}, t1, 0.01).signed_distance, d,
              1e-12);
  EXPECT_NEAR(path.nearest({mid[0] + d / std::sqrt(2.0), mid[1] + d / std::sqrt(2.0), 0.0}, t1, 0.01).signed_distance, -d,
              1e-12);
  // Outside the top corner (0, 20), in the wedge between the two edges' normals: the corner
  // point itself is nearest.
  const double t_corner = plan.moves()[1].t_end;
  const ContourPoint corner = path.nearest({0.0, 20.7, 0.0}, t_corner, 0.05);
  EXPECT_NEAR(corner.distance, 0.7, 1e-12);
  EXPECT_NEAR(corner.nearest[1], 20.0, 1e-12);
  EXPECT_EQ(path.kind_at(t1), PathKind::Line);
  EXPECT_EQ(path.kind_at(plan.duration() + 1.0), PathKind::Stop);
  EXPECT_EQ(path.kind_at(0.5 * plan.moves()[0].t_end), PathKind::Rapid);
}

/// The command followed by an underdamped second-order loop per axis (30 Hz, zeta 0.3): it lags
/// on the lines and arcs and overshoots every corner and exact stop.
std::vector<std::vector<double>> overshooting(const Trajectory& c) {
  const double wn = 2.0 * kPi * 30.0, zeta = 0.3, ts = c.ts;
  std::vector<std::vector<double>> out(c.positions.size());
  for (std::size_t i = 0; i < c.positions.size(); ++i) {
    double x = c.positions[i].front(), v = 0.0;
    for (const double command : c.positions[i]) {
      v += ts * (wn * wn * (command - x) - 2.0 * zeta * wn * v);
      x += ts * v;
      out[i].push_back(x);
    }
  }
  return out;
}

TEST(Contour, SignChangesOnlyWhereTheDistancePassesZero) {
  // Lagging and overshooting through the rapid -> circle -> rapid joins and the diamond's corners
  // (exact stops, overshoots of 10 % and more): wherever the signed error changes sign between
  // two samples, both errors are within the point's own motion of zero, i.e. the sign flips only
  // where the distance is (nearly) zero, never at a join.
  for (const Program& program : {make_circle_program({}), make_diamond_program({})}) {
    const MotionPlan plan = plan_motion(program, limits());
    const ContourPath path(program, plan);
    const Trajectory c = sample(plan, {Axis::X, Axis::Y});
    const auto actual = overshooting(c);
    const std::vector<double> e = contour_errors(path, c.axes, actual);
    double largest = 0.0;
    for (std::size_t k = 1; k < e.size(); ++k) {
      largest = std::max(largest, std::abs(e[k]));
      if ((e[k] > 0.0) == (e[k - 1] > 0.0)) continue;
      const double moved = std::hypot(actual[0][k] - actual[0][k - 1], actual[1][k] - actual[1][k - 1]);
      EXPECT_LE(std::abs(e[k]) + std::abs(e[k - 1]), moved + 1e-12) << program.name << " sample " << k;
    }
    EXPECT_GT(largest, 0.03) << program.name;  // the test means something: 30-40 um contour errors
  }
}

TEST(Contour, AnotherPassOfThePathNearbyIsNotTheContour) {
  // A hairpin: right along y = 0, up 0.3 mm, back along y = 0.3. A point 0.2 mm above the first
  // leg, 1 mm behind the commanded point, is 0.1 mm from the return leg, which the command runs
  // on within the 0.2 s window: the time window alone would measure to the return leg; the
  // path-length rule (4 x 1.02 mm around the commanded point) keeps to the leg being followed.
  const Program program = parse_iso("G01 X10 Y0 F6000\nG01 X10 Y0.3\nG01 X0 Y0.3\n", "hairpin.nc");
  InterpolationLimits l = limits();
  l.corner_angle_deg = 100.0;  // no stops at the hairpin: the return leg comes within the window
  const MotionPlan plan = plan_motion(program, l);
  const ContourPath path(program, plan);
  const Trajectory c = sample(plan, {Axis::X, Axis::Y});
  std::size_t k = 0;
  while (c.positions[0][k] < 6.0) ++k;
  const Point p{c.positions[0][k] - 1.0, 0.2, 0.0};
  EXPECT_NEAR(path.nearest(k, p).signed_distance, 0.2, 1e-12);
  EXPECT_NEAR(path.nearest(p, static_cast<double>(k) * c.ts, 0.2).distance, 0.1, 1e-12);  // window alone
  EXPECT_NEAR(CommandPolyline(c, 0.2).nearest(k, p).signed_distance, 0.2, 1e-12);
}

/// Brute force: the smallest distance to the continuous path sampled every `dt` over
/// [t - window, t + window] (the documented neighbourhood: the part run within the window).
double brute_force(const MotionPlan& plan, const Point& p, double t, double window, double dt) {
  const auto distance = [&](const Point& q) { return std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]); };
  double best = std::numeric_limits<double>::infinity();
  const double t0 = std::max(0.0, t - window), t1 = std::min(plan.duration(), t + window);
  for (double tau = t0;; tau += dt) {
    best = std::min(best, distance(plan.position_at(std::min(tau, t1))));
    if (tau >= t1) break;
  }
  // The open ends continue along their tangents (direction from a step of 3e-5 s into the path:
  // from rest at 1000 mm/s^2 along it, 4.5e-7 mm: curvature (1/5 mm) and rounding (1e-14 mm)
  // each tilt the direction by under 1e-7, under 1e-6 mm at 10 mm from the end).
  const auto ray = [&](const Point& end, const Point& inside) {
    Point u{end[0] - inside[0], end[1] - inside[1], end[2] - inside[2]};
    const double len = std::hypot(u[0], u[1], u[2]);
    for (double& c : u) c /= len;
    const double along = std::max(0.0, (p[0] - end[0]) * u[0] + (p[1] - end[1]) * u[1] + (p[2] - end[2]) * u[2]);
    return distance({end[0] + along * u[0], end[1] + along * u[1], end[2] + along * u[2]});
  };
  if (t0 == 0.0) best = std::min(best, ray(plan.position_at(0.0), plan.position_at(3e-5)));
  if (t1 == plan.duration()) best = std::min(best, ray(plan.position_at(t1), plan.position_at(t1 - 3e-5)));
  return best;
}

void check_against_brute_force(const Program& program, std::uint64_t seed, double spread) {
  const MotionPlan plan = plan_motion(program, limits());
  const ContourPath path(program, plan);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> time(0.0, plan.duration()), offset(-spread, spread);
  const double window = 0.05, dt = 2e-6;
  const double max_speed = 200.0;  // mm/s: bounds the spacing of the brute force's points
  for (int i = 0; i < 30; ++i) {
    const double t = std::round(time(rng) / plan.ts()) * plan.ts();  // windows end on samples
    Point p = plan.position_at(t);
    for (double& c : p) c += offset(rng);
    const ContourPoint exact = path.nearest(p, t, window);
    const double brute = brute_force(plan, p, t, window, dt);
    SCOPED_TRACE(::testing::Message() << "t = " << t);
    // The exact point lies on the path, so it is never farther than the brute force's best vertex
    // by more than rounding (1e-6 at the open ends, whose direction the brute force takes from a
    // short step); the brute force misses the exact point by at most half its spacing.
    EXPECT_LE(exact.distance, brute + 1e-6);
    EXPECT_GE(exact.distance, brute - 0.5 * max_speed * dt - 1e-9);
  }
}

TEST(Contour, MatchesBruteForceOnCirclesLinesAndCorners) {
  check_against_brute_force(make_circle_program({}), 1, 0.5);
  check_against_brute_force(make_diamond_program({}), 2, 0.5);
  check_against_brute_force(parse_iso("G01 X10 Y5 F9000\nG03 X20 Y15 R10\nG01 X0 Y30\nG02 X-5 Y20 R8\n", "mix.nc"), 3, 1.0);
}

TEST(Contour, MatchesBruteForceOnHelicesAndSpirals) {
  // A helix (Z rises 4 mm over 1.5 turns' worth of arc) and a spiral (end radius 12 vs start 10,
  // accepted by the lenient radius check of the reader and followed as a linear spiral).
  check_against_brute_force(parse_iso("G17 G01 X10 Y0 F6000\nG03 X-10 Y0 Z4 I-10 J0\n", "helix.nc"), 4, 0.8);
  // Far from a steep full-turn helix, where the distance has several local minima along it.
  check_against_brute_force(parse_iso("G17 G01 X5 Y0 F6000\nG03 X5 Y0 Z12 I-5 J0\n", "steep.nc"), 6, 8.0);
  ParseOptions lenient;
  lenient.arc_tolerance_abs_mm = 5.0;
  check_against_brute_force(parse_iso("G17 G01 X10 Y0 F6000\nG03 X0 Y12 I-10 J0\n", "spiral.nc", lenient), 5, 0.8);
}

TEST(Contour, CommandedTrajectoryHasNoContourErrorAndUnitsScale) {
  const Program program = make_diamond_program({});
  const MotionPlan plan = plan_motion(program, limits());
  const Trajectory commanded = sample(plan, {Axis::X, Axis::Y});
  const ContourPath path(program, plan);
  const std::vector<double> e = contour_errors_in_window(path, commanded.axes, commanded.positions, commanded.ts);
  ASSERT_EQ(e.size(), commanded.size());
  for (double v : e) EXPECT_LE(std::abs(v), 1e-9);

  // Shifting every actual point by 0.1 mm in +X gives the same contour errors in mm and in um.
  std::vector<std::vector<double>> shifted = commanded.positions;
  for (double& x : shifted[0]) x += 0.1;
  const std::vector<double> mm = contour_errors_in_window(path, commanded.axes, shifted, commanded.ts);
  ContourProgramOptions um_options;
  um_options.size_mm = 40000.0;
  um_options.feed_mm_min = 12000.0 * 1000.0;
  InterpolationLimits um_limits = limits();
  um_limits.accel *= 1000.0;
  um_limits.rapid_feed_mm_min *= 1000.0;
  const Program um_program = make_diamond_program(um_options);
  const MotionPlan um_plan = plan_motion(um_program, um_limits);
  const ContourPath um_path(um_program, um_plan);
  std::vector<std::vector<double>> um = shifted;
  for (auto& column : um)
    for (double& v : column) v *= 1000.0;
  const std::vector<double> in_um = contour_errors_in_window(um_path, commanded.axes, um, commanded.ts);
  ASSERT_EQ(in_um.size(), mm.size());
  for (std::size_t k = 0; k < mm.size(); k += 97) EXPECT_NEAR(in_um[k], 1000.0 * mm[k], 1e-9 * 1000.0 + 1e-9 * std::abs(in_um[k]));
}

TEST(Contour, BadInput) {
  const Program still = parse_iso("G04 P1\n", "dwell.nc");
  const MotionPlan plan = plan_motion(still, limits());
  const ContourPath path(still, plan);
  EXPECT_EQ(path.segment_count(), 0u);
  EXPECT_THROW((void)path.nearest({0.0, 0.0, 0.0}, 0.0), core::InputError);
  const Program program = make_circle_program({});
  const ContourPath circle(program, plan_motion(program, limits()));
  EXPECT_THROW((void)circle.nearest({std::nan(""), 0.0, 0.0}, 0.0), core::InputError);
  EXPECT_THROW((void)contour_errors_in_window(circle, {Axis::X}, {{0.0}, {0.0}}, 0.001), core::InputError);
  ContourProgramOptions bad;
  bad.size_mm = -1.0;
  EXPECT_THAT([&] { (void)make_circle_program(bad); }, testing::ThrowsMessage<core::InputError>(testing::HasSubstr("size_mm")));
}

}  // namespace
}  // namespace servotwin::motion
