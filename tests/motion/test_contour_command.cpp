// The program's path followed by a recorded command (ContourPath::from_command) and the command's
// own path (CommandPolyline). References: servotwin's own plan (a command that IS the plan must give
// the plan's progress and contour errors to rounding), closed forms (a translated trace gives back
// the translation; a circle's radial offset; a moving-average command's distance to a straight
// edge is zero and at a corner the distance to the corner's two lines, computed here directly),
// and a brute-force scan over every chord of the window.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/contour.hpp"
#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/identification_program.hpp"
#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion {
namespace {

InterpolationLimits command_limits() {
  InterpolationLimits l;
  l.ts = 0.001;
  l.accel = 2000.0;
  return l;
}

/// The plan's own commanded trajectory, translated by `offset`.
Trajectory commanded(const MotionPlan& plan, const std::vector<Axis>& axes, const Point& offset = {}) {
  Trajectory t = sample(plan, axes);
  for (std::size_t i = 0; i < t.axes.size(); ++i)
    for (double& v : t.positions[i]) v += offset[static_cast<std::size_t>(t.axes[i])];
  return t;
}

TEST(ContourFromCommand, ThePlansOwnCommandGivesThePlansProgressAndErrors) {
  const Program program = make_diamond_program({});
  const MotionPlan plan = plan_motion(program, command_limits());
  const Trajectory c = commanded(plan, {Axis::X, Axis::Y});
  const ContourPath planned(program, plan);
  const ContourPath traced = ContourPath::from_command(program, c);
  EXPECT_LE(traced.match().max_deviation, 1e-12);
  EXPECT_NEAR(traced.match().progress_end, traced.match().path_length, 1e-9);
  EXPECT_NEAR(traced.match().path_length, 20.0 + 4.0 * std::hypot(20.0, 20.0) + 20.0, 1e-9);
  for (std::size_t k = 0; k < c.size(); k += 7)
    EXPECT_NEAR(traced.progress_at(static_cast<double>(k) * c.ts), planned.progress_at(static_cast<double>(k) * c.ts), 1e-9);
  // Contour errors of a lagging, displaced point: the same against both.
  std::vector<std::vector<double>> actual = c.positions;
  for (std::size_t i = 0; i < 2; ++i) {
    std::rotate(actual[i].rbegin(), actual[i].rbegin() + 8, actual[i].rend());
    for (double& v : actual[i]) v += i == 0 ? 0.03 : -0.01;
  }
  const std::vector<double> a = contour_errors(planned, c.axes, actual);
  const std::vector<double> b = contour_errors(traced, c.axes, actual);
  for (std::size_t k = 8; k < c.size(); ++k) ASSERT_NEAR(a[k], b[k], 1e-9) << k;
  // Kinds: the segment under the command, Stop at the exact stops.
  std::size_t lines = 0, stops = 0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    lines += traced.kind(k) == PathKind::Line;
    stops += traced.kind(k) == PathKind::Stop;
  }
  EXPECT_GT(lines, c.size() / 2);
  EXPECT_GT(stops, 0u);
}

TEST(ContourFromCommand, BackAndForthMovesAreFollowedMoveByMoveAndAWorkOffsetIsFound) {
  IdentificationOptions o;
  o.axes = {Axis::X, Axis::Y};
  o.moves = 60;
  o.seed = 11;
  const Program program = make_identification_program(o);
  const MotionPlan plan = plan_motion(program, command_limits());
  const ContourPath planned(program, plan);
  // The trace in machine coordinates: program coordinates + (3, -2); found from the end point.
  const Point offset{3.0, -2.0, 0.0};
  const Trajectory c = commanded(plan, {Axis::X, Axis::Y}, offset);
  const ContourPath traced = ContourPath::from_command(program, c);
  EXPECT_NEAR(traced.match().offset[0], 3.0, 1e-12);
  EXPECT_NEAR(traced.match().offset[1], -2.0, 1e-12);
  EXPECT_LE(traced.match().max_deviation, 1e-9);
  for (std::size_t k = 0; k < c.size(); ++k) {
    const double t = static_cast<double>(k) * c.ts;
    ASSERT_NEAR(traced.progress_at(t), planned.progress_at(t), 1e-6) << "sample " << k;
  }
  // The nearest points come back in the trace's coordinates.
  const ContourPoint q = traced.nearest(c.size() / 2, {c.positions[0][c.size() / 2], c.positions[1][c.size() / 2], 0.0});
  EXPECT_NEAR(q.distance, 0.0, 1e-9);
  // Told the offset, it is used as given; told a wrong one, the deviation says so.
  CommandMatchOptions wrong;
  wrong.offset = Point{0.0, 0.0, 0.0};
  EXPECT_GT(ContourPath::from_command(program, c, wrong).match().max_deviation, 1.0);
}

/// Moving average of 2 m + 1 samples: corners cut, straight parts unchanged.
Trajectory smoothed(const Trajectory& t, std::size_t m) {
  Trajectory out = t;
  for (std::size_t i = 0; i < t.axes.size(); ++i) {
    const auto& x = t.positions[i];
    for (std::size_t k = 0; k < x.size(); ++k) {
      double sum = 0.0;
      for (std::size_t j = k >= m ? k - m : 0; j <= std::min(x.size() - 1, k + m); ++j) sum += x[j];
      out.positions[i][k] = sum / static_cast<double>(std::min(x.size() - 1, k + m) - (k >= m ? k - m : 0) + 1);
    }
  }
  return out;
}

TEST(ContourFromCommand, ABlendedCommandIsMatchedWithinItsCornerCut) {
  // A diamond without stops (blending), its command smoothed: corners cut like a controller's
  // blend. The largest deviation is at a corner: the distance of the cut point to the nearer of
  // the corner's two edges, computed here for every sample against all four edges.
  ContourProgramOptions o;
  o.path_control = PathControl::Blend;
  const Program program = make_diamond_program(o);
  InterpolationLimits l = command_limits();
  l.corner_angle_deg = 100.0;  // run through the 90 deg corners
  const Trajectory c = smoothed(commanded(plan_motion(program, l), {Axis::X, Axis::Y}), 40);
  CommandMatchOptions options;
  options.tolerance_mm = 2.0;
  const ContourPath traced = ContourPath::from_command(program, c, options);
  const std::array<std::array<double, 4>, 5> lines{{{0, 0, 20, 0}, {20, 0, 0, 20}, {0, 20, -20, 0}, {-20, 0, 0, -20}, {0, -20, 20, 0}}};
  double expected = 0.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    double d = 1e9;
    for (const auto& s : lines) {
      const double dx = s[2] - s[0], dy = s[3] - s[1];
      const double u = std::clamp(((c.positions[0][k] - s[0]) * dx + (c.positions[1][k] - s[1]) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
      d = std::min(d, std::hypot(c.positions[0][k] - s[0] - u * dx, c.positions[1][k] - s[1] - u * dy));
    }
    expected = std::max(expected, d);
  }
  EXPECT_GT(expected, 0.1);  // the corners are really cut
  EXPECT_NEAR(traced.match().max_deviation, expected, 1e-9);
  EXPECT_NEAR(traced.match().progress_end, traced.match().path_length, 1.0);  // the average ends short of the stop
  for (std::size_t k = 1; k < c.size(); ++k)
    ASSERT_GE(traced.progress_at(static_cast<double>(k) * c.ts), traced.progress_at(static_cast<double>(k - 1) * c.ts));
}

TEST(ContourFromCommand, MissingAxesAndEmptyProgramsAreRefused) {
  const Program program = make_diamond_program({});
  const Trajectory c = commanded(plan_motion(program, command_limits()), {Axis::X});
  EXPECT_THAT([&] { (void)ContourPath::from_command(program, c); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("no y column")));
  const Trajectory xy = commanded(plan_motion(program, command_limits()), {Axis::X, Axis::Y});
  EXPECT_THROW((void)ContourPath::from_command(parse_iso("G04 P1\n", "dwell.nc"), xy), core::InputError);
}

TEST(CommandPolyline, CircleRadialOffsetAndSide) {
  const Program program = make_circle_program({});
  const MotionPlan plan = plan_motion(program, command_limits());
  const Trajectory c = commanded(plan, {Axis::X, Axis::Y});
  const CommandPolyline path(c, 0.2);
  // On the circle (centre 0, radius 20): a point 0.1 mm outside is right of counter-clockwise
  // travel (negative), one inside positive. On the radius through a vertex, the chords' distance
  // differs from the circle's by 0.1 (1 - cos(delta / 2)) = 0.1 delta^2 / 8 (delta the angle a chord spans).
  const double t = 0.5 * (plan.moves()[1].t_start + plan.moves()[1].t_end);
  const auto k = static_cast<std::size_t>(std::lround(t / c.ts));
  const double angle = std::atan2(c.positions[1][k], c.positions[0][k]);
  const double delta = std::hypot(c.positions[0][k + 1] - c.positions[0][k], c.positions[1][k + 1] - c.positions[1][k]) / 20.0;
  for (const double rho : {19.9, 20.1}) {
    const ContourPoint q = path.nearest(k, {rho * std::cos(angle), rho * std::sin(angle), 0.0});
    EXPECT_NEAR(q.signed_distance, 20.0 - rho, 0.1 * delta * delta / 8.0 * 1.01 + 1e-12);
  }
  EXPECT_EQ(path.kind(k), PathKind::Move);
}

TEST(CommandPolyline, PruningFindsTheBruteForceNearestChord) {
  const Program program = parse_iso("G01 X10 Y5 F9000\nG03 X20 Y15 R10\nG01 X0 Y30\nG02 X-5 Y20 R8\n", "mix.nc");
  const Trajectory c = commanded(plan_motion(program, command_limits()), {Axis::X, Axis::Y});
  const double window = 0.05;
  const CommandPolyline path(c, window);
  const auto w = static_cast<std::size_t>(std::lround(window / c.ts));
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::size_t> sample(0, c.size() - 1);
  std::uniform_real_distribution<double> spread(-2.0, 2.0);
  for (int i = 0; i < 200; ++i) {
    const std::size_t k = sample(rng);
    const Point p{c.positions[0][k] + spread(rng), c.positions[1][k] + spread(rng), 0.0};
    double best = 1e9;
    for (std::size_t j = k > w ? k - w : 0; j + 1 < c.size() && j < k + w; ++j) {
      const double ax = c.positions[0][j], ay = c.positions[1][j];
      const double dx = c.positions[0][j + 1] - ax, dy = c.positions[1][j + 1] - ay;
      const double len2 = dx * dx + dy * dy;
      // The first and last chords continue past the command's ends (the open-end rule).
      const double lo = j == 0 ? -1e9 : 0.0, hi = j + 2 == c.size() ? 1e9 : 1.0;
      const double u = len2 > 0.0 ? std::clamp(((p[0] - ax) * dx + (p[1] - ay) * dy) / len2, lo, hi) : 0.0;
      best = std::min(best, std::hypot(p[0] - ax - u * dx, p[1] - ay - u * dy));
    }
    EXPECT_NEAR(path.nearest(k, p).distance, best, 1e-12) << "sample " << k;
  }
}

}  // namespace
}  // namespace servotwin::motion
