// Prediction of tracking and contour errors from axis models: the steady-state contour error of a
// circle against the closed form R (1 - |G(j omega)|) of a linear model, alignment and scoring of
// a measured capture (a shifted copy of the prediction itself must score perfectly and be found
// at its shift), and the errors for models and captures that do not fit the program.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "servotwin/core/error.hpp"
#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/vcnc/prediction.hpp"

namespace servotwin::vcnc {
namespace {

using ::testing::HasSubstr;

/// A P-PI-like loop (thesis Table 3.3 structure: b0 = b1 = 0), no friction: linear.
rapid::ModelCoefficients lagging_loop() {
  rapid::ModelCoefficients c;
  c.a1 = 372.76;
  c.a2 = 62009.83;
  c.a3 = 1527104.87;
  c.b2 = 11106.33;
  return c;
}

std::vector<AxisModelSpec> xy_models(const rapid::ModelCoefficients& c) {
  return {{"x", rapid::AxisModel(c, 0.001), 0, "x.json"}, {"y", rapid::AxisModel(c, 0.001), 0, "y.json"}};
}

motion::InterpolationLimits limits() {
  motion::InterpolationLimits l;
  l.accel = 2000.0;
  return l;
}

TEST(Prediction, SteadyCircleContourErrorIsTheClosedForm) {
  // At constant speed v on a circle of radius R both axes see sinusoids of omega = v / R, so a
  // linear model's steady response is a circle of radius R |G(j omega)|: contour error
  // R (1 - |G|), positive (inside) on this counter-clockwise circle.
  motion::ContourProgramOptions o;
  o.size_mm = 40.0;
  const motion::Program circle = motion::make_circle_program(o);
  const Prediction p = predict(circle, "circle", limits(), xy_models(lagging_loop()));
  ASSERT_EQ(p.axes.size(), 2u);
  // The arc's speed is capped below F12000 by the centripetal share of the acceleration
  // (sqrt(0.866 * 2000 mm/s^2 * 20 mm) = 186 mm/s); take it from the commanded samples.
  const std::size_t mid = static_cast<std::size_t>(0.7 / p.ts);
  const double v = std::hypot(p.command[0][mid + 1] - p.command[0][mid - 1], p.command[1][mid + 1] - p.command[1][mid - 1]) /
                   (2.0 * p.ts);
  // (less the time scaling that makes the arc end on a sample: under one sample in 0.86 s).
  EXPECT_NEAR(v, std::sqrt(std::sqrt(0.75) * 2000.0 * 20.0), 0.002 * v);
  const double omega = v / 20.0;
  const double gain = std::abs(rapid::AxisModel(lagging_loop(), 0.001).tracking().frequency_response(omega));
  const double expected = 20.0 * (1.0 - gain);
  // Steady arc motion: the start transient (0.2 s to 0.3 s ramp-up, slowest pole 4.7 Hz) has
  // decayed and the deceleration (from 0.95 s) has not begun.
  std::size_t checked = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double t = static_cast<double>(k) * p.ts;
    if (p.kind[k] != motion::PathKind::Arc || t < 0.60 || t > 0.85) continue;
    EXPECT_NEAR(p.contour_error[k], expected, 0.01 * expected) << "t = " << t;
    ++checked;
  }
  EXPECT_GT(checked, 100u);
  EXPECT_GT(expected, 0.1);  // the test means something: a visible contour error
}

TEST(Prediction, ShiftedCopyOfThePredictionIsFoundAndScoresPerfectly) {
  const motion::Program diamond = motion::make_diamond_program({});
  const Prediction p = predict(diamond, "diamond", limits(), xy_models(lagging_loop()));
  // A "measurement" that starts 37 samples early (the scope was triggered before the program).
  core::Capture capture;
  capture.ts = p.ts;
  for (std::size_t i = 0; i < p.axes.size(); ++i) {
    core::AxisTrace trace;
    trace.name = motion::axis_name(p.axes[i]);
    trace.cmd.assign(37, p.command[i].front());
    trace.act.assign(37, p.predicted[i].front());
    trace.cmd.insert(trace.cmd.end(), p.command[i].begin(), p.command[i].end());
    trace.act.insert(trace.act.end(), p.predicted[i].begin(), p.predicted[i].end());
    capture.axes.push_back(std::move(trace));
  }
  const MeasuredComparison m = compare_with_capture(p, capture, "measured.csv");
  EXPECT_EQ(m.offset, 37);
  EXPECT_EQ(m.count, p.size());
  EXPECT_EQ(m.command_mismatch_rms, 0.0);
  ASSERT_FALSE(m.scores.empty());
  for (const auto& s : m.scores) EXPECT_LE(s.metrics.nrmse, 1e-12) << s.quantity << " " << s.kind;
  bool has_line = false, has_contour = false;
  for (const auto& s : m.scores) {
    has_line |= s.kind == "line";
    has_contour |= s.quantity == "contour";
  }
  EXPECT_TRUE(has_line);
  EXPECT_TRUE(has_contour);
  for (std::size_t k = 0; k < p.size(); ++k) EXPECT_NEAR(m.contour_error[k], p.contour_error[k], 1e-12);
}

TEST(Prediction, ModelsAndCapturesThatDoNotFitAreRejected) {
  const motion::Program diamond = motion::make_diamond_program({});
  const auto c = lagging_loop();
  EXPECT_THAT([&] { (void)predict(diamond, "d.nc", limits(), {{"x", rapid::AxisModel(c, 0.001), 0, "x.json"}}); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("moves axis Y but no model")));
  EXPECT_THAT([&] {
    (void)predict(diamond, "d.nc", limits(),
                  {{"x", rapid::AxisModel(c, 0.001), 0, "x.json"}, {"y", rapid::AxisModel(c, 0.002), 0, "y.json"}});
  }, testing::ThrowsMessage<core::InputError>(HasSubstr("y.json")));
  EXPECT_THAT([&] {
    (void)predict(diamond, "d.nc", limits(),
                  {{"x", rapid::AxisModel(c, 0.001), 0, "a.json"}, {"x", rapid::AxisModel(c, 0.001), 0, "b.json"}});
  }, testing::ThrowsMessage<core::InputError>(HasSubstr("second model for axis x")));
  EXPECT_THAT([&] { (void)predict(diamond, "d.nc", limits(), {{"q", rapid::AxisModel(c, 0.001), 0, "q.json"}}); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("not x, y or z")));
  EXPECT_THROW((void)predict(diamond, "d.nc", limits(), {}), core::InputError);

  // A capture of another program (the circle) does not match the diamond.
  const Prediction p = predict(diamond, "d.nc", limits(), xy_models(c));
  const Prediction other = predict(motion::make_circle_program({}), "c.nc", limits(), xy_models(c));
  core::Capture capture;
  capture.ts = 0.001;
  for (std::size_t i = 0; i < 2; ++i)
    capture.axes.push_back({motion::axis_name(other.axes[i]), other.command[i], other.predicted[i], {}});
  EXPECT_THAT([&] { (void)compare_with_capture(p, capture, "circle.csv"); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("circle.csv")));
  capture.ts = 0.002;
  EXPECT_THAT([&] { (void)compare_with_capture(p, capture, "slow.csv"); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("sample period")));
  capture.ts = 0.001;
  capture.axes.pop_back();
  EXPECT_THAT([&] { (void)compare_with_capture(p, capture, "x-only.csv"); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("no axis y")));
}


/// A trace whose command is `command` (axes in X, Y order) and whose measured position is the
/// models' response to it: a machine that IS the models.
core::Capture trace_of(const std::vector<std::vector<double>>& command, const rapid::ModelCoefficients& c, double ts = 0.001) {
  core::Capture trace;
  trace.ts = ts;
  for (std::size_t i = 0; i < command.size(); ++i) {
    rapid::ModelSimulationOptions sim;
    sim.initial_position = command[i].front();
    trace.axes.push_back({i == 0 ? "x" : "y", command[i], rapid::AxisModel(c, 0.001).simulate(command[i], sim).position, {}});
  }
  return trace;
}

TEST(Prediction, OneThreadAndThreeGiveTheSamePrediction) {
  // predict shares the axes' simulations, the contour path's construction and the contour errors
  // among threads (PredictionOptions::workers); each piece of work is the same whichever thread
  // does it, so the numbers agree bit for bit. 40 circles: 35 s, long enough for several parts.
  std::string text = "G17 G90 G01 X20 Y0 F6000\n";
  for (int i = 0; i < 40; ++i) text += "G03 X20 Y0 I-20 J0\nG01 X0 Y20\nG01 X20 Y0\n";
  const motion::Program program = motion::parse_iso(text, "circles.nc");
  PredictionOptions one, three;
  one.workers = 1;
  three.workers = 3;  // more than the axes of a stage: every stage is cut
  const Prediction a = predict(program, "circles.nc", limits(), xy_models(lagging_loop()), one);
  const Prediction b = predict(program, "circles.nc", limits(), xy_models(lagging_loop()), three);
  ASSERT_GT(a.size(), 30000u);
  EXPECT_EQ(a.predicted, b.predicted);
  EXPECT_EQ(a.contour_error, b.contour_error);
  EXPECT_EQ(a.kind, b.kind);
}

TEST(PredictionFromCommand, TheInterpolatorsOwnCommandGivesTheSamePrediction) {
  const motion::Program diamond = motion::make_diamond_program({});
  const Prediction p = predict(diamond, "d.nc", limits(), xy_models(lagging_loop()));
  const core::Capture trace = trace_of(p.command, lagging_loop());
  const Prediction q = predict_from_command(trace, "trace.csv", &diamond, "d.nc", xy_models(lagging_loop()));
  ASSERT_EQ(q.size(), p.size());
  for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(q.predicted[i], p.predicted[i]);
  for (std::size_t k = 0; k < p.size(); ++k) ASSERT_NEAR(q.contour_error[k], p.contour_error[k], 1e-9) << k;
  const MeasuredComparison m = compare_with_trace(q, trace, "trace.csv");
  EXPECT_EQ(m.count, p.size());
  for (const auto& s : m.scores) EXPECT_LE(s.metrics.nrmse, 1e-12) << s.quantity << " " << s.kind;
  EXPECT_TRUE(q.warnings.empty());
}

TEST(PredictionFromCommand, AnotherControllersCommandIsFollowedWhereTheCaptureComparisonRefusesIt) {
  // A controller with half the acceleration that runs through the diamond's corners (G64): its
  // command is millimetres away from servotwin's interpolation of the program at the same time.
  motion::ContourProgramOptions o;
  o.path_control = motion::PathControl::Blend;
  const motion::Program diamond = motion::make_diamond_program(o);
  motion::InterpolationLimits other = limits();
  other.accel = 1000.0;
  other.corner_angle_deg = 100.0;
  const motion::Trajectory command = motion::interpolate(diamond, other, {motion::Axis::X, motion::Axis::Y});
  const core::Capture trace = trace_of(command.positions, lagging_loop());
  const Prediction ours = predict(diamond, "d.nc", limits(), xy_models(lagging_loop()));
  EXPECT_THAT([&] { (void)compare_with_capture(ours, trace, "trace.csv"); },
              testing::ThrowsMessage<core::InputError>(HasSubstr("--command")));
  EXPECT_FALSE(ours.notes.empty());  // blending: the note that points to the recorded command
  const Prediction q = predict_from_command(trace, "trace.csv", &diamond, "d.nc", xy_models(lagging_loop()));
  const MeasuredComparison m = compare_with_trace(q, trace, "trace.csv");
  for (const auto& s : m.scores) EXPECT_LE(s.metrics.nrmse, 1e-12) << s.quantity << " " << s.kind;
  // The contour error is measured against the programmed edges: the machine rounds the corners.
  double largest = 0.0;
  for (double e : q.contour_error) largest = std::max(largest, std::abs(e));
  EXPECT_GT(largest, 0.05);
}

TEST(PredictionFromCommand, WithoutAProgramTheCommandsOwnPathIsTheReference) {
  const motion::Program circle = motion::make_circle_program({});
  const Prediction p = predict(circle, "c.nc", limits(), xy_models(lagging_loop()));
  core::Capture trace = trace_of(p.command, lagging_loop());
  const Prediction q = predict_from_command(trace, "trace.csv", nullptr, "", xy_models(lagging_loop()));
  // On the arc, away from its ends, the polyline's chords give the circle's errors to within their
  // sagitta (v ts)^2 / 8R = (0.186 mm)^2 / 160 mm = 2.2e-4 mm.
  std::size_t checked = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double t = static_cast<double>(k) * p.ts;
    if (p.kind[k] != motion::PathKind::Arc || t < 0.4 || t > 0.8) continue;
    EXPECT_NEAR(q.contour_error[k], p.contour_error[k], 2.5e-4) << k;
    EXPECT_EQ(q.kind[k], motion::PathKind::Move);
    ++checked;
  }
  EXPECT_GT(checked, 100u);
}

TEST(PredictionFromCommand, TracesThatDoNotFitAreRejected) {
  const auto c = lagging_loop();
  const motion::Program diamond = motion::make_diamond_program({});
  const Prediction p = predict(diamond, "d.nc", limits(), xy_models(c));
  core::Capture trace = trace_of(p.command, c);
  const auto rejects = [&](const core::Capture& t, const motion::Program* program, const std::vector<AxisModelSpec>& models,
                           const std::string& text) {
    EXPECT_THAT([&] { (void)predict_from_command(t, "trace.csv", program, "d.nc", models); },
                testing::ThrowsMessage<core::InputError>(HasSubstr(text)));
  };
  core::Capture slow = trace;
  slow.ts = 0.002;
  rejects(slow, &diamond, xy_models(c), "sample period");
  core::Capture x_only = trace;
  x_only.axes.pop_back();
  rejects(x_only, &diamond, xy_models(c), "no commanded position of axis y");
  rejects(trace, &diamond, {{"x", rapid::AxisModel(c, 0.001), 0, "x.json"}}, "moves but no model");
  rejects(trace, nullptr, {{"x", rapid::AxisModel(c, 0.001), 0, "x.json"}}, "moves but no model");
  // A run of another program (the circle) is not a run of the diamond.
  const Prediction other = predict(motion::make_circle_program({}), "c.nc", limits(), xy_models(c));
  rejects(trace_of(other.command, c), &diamond, xy_models(c), "leaves");
  // A trace that stops a third of the way.
  core::Capture cut = trace;
  for (auto& a : cut.axes) {
    a.cmd.resize(a.cmd.size() / 3);
    a.act.resize(a.act.size() / 3);
  }
  rejects(cut, &diamond, xy_models(c), "covers");
  EXPECT_THAT([&] { (void)compare_with_trace(p, cut, "cut.csv"); }, testing::ThrowsMessage<core::InputError>(HasSubstr("cut.csv")));
}

TEST(Prediction, AProgramWithoutAStatedModeIsWarnedAbout) {
  motion::ContourProgramOptions o;
  o.path_control = motion::PathControl::Unstated;
  const Prediction p = predict(motion::make_diamond_program(o), "d.nc", limits(), xy_models(lagging_loop()));
  ASSERT_EQ(p.warnings.size(), 1u);
  EXPECT_THAT(p.warnings.front(), HasSubstr("states no path-control mode"));
  EXPECT_TRUE(predict(motion::make_diamond_program({}), "d.nc", limits(), xy_models(lagging_loop())).warnings.empty());
}

}  // namespace
}  // namespace servotwin::vcnc
