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

}  // namespace
}  // namespace servotwin::vcnc
