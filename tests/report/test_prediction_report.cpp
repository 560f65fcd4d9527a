// The prediction report: its sections and charts carry the prediction's numbers unchanged, and the
// path chart's magnified points sit on the line from their nearest path point, at the stated
// factor (checked on a circle, where that is a radius: R - factor x contour error).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "servotwin/motion/contour_programs.hpp"
#include "servotwin/report/prediction_report.hpp"

namespace servotwin::report {
namespace {

vcnc::Prediction circle_prediction() {
  rapid::ModelCoefficients c;  // thesis Table 3.3 structure (P-PI): a visible contour error
  c.a1 = 372.76;
  c.a2 = 62009.83;
  c.a3 = 1527104.87;
  c.b2 = 11106.33;
  motion::InterpolationLimits limits;
  limits.accel = 2000.0;
  return vcnc::predict(motion::make_circle_program({}), "circle.nc", limits,
                       {{"x", rapid::AxisModel(c, 0.001), 0, "x"}, {"y", rapid::AxisModel(c, 0.001), 0, "y"}});
}

const Chart* find_chart(const Document& doc, const std::string& title_start) {
  for (const auto& s : doc.sections)
    for (const auto& c : s.charts)
      if (c.title.rfind(title_start, 0) == 0) return &c;
  return nullptr;
}

TEST(PredictionReport, ChartsCarryThePredictionAndThePathIsMagnifiedExactly) {
  const vcnc::Prediction p = circle_prediction();
  const Document doc = prediction_report("circle.nc", p, nullptr);
  std::vector<std::string> titles;
  for (const auto& s : doc.sections) titles.push_back(s.title);
  EXPECT_THAT(titles, ::testing::ElementsAre("circle.nc: summary", "circle.nc: tracking errors", "circle.nc: contour error",
                                           "circle.nc: path"));

  const Chart* over_time = find_chart(doc, "Contour error over time");
  ASSERT_NE(over_time, nullptr);
  ASSERT_EQ(over_time->series.size(), 1u);  // no measurement
  for (std::size_t k = 0; k < p.size(); ++k) EXPECT_DOUBLE_EQ(over_time->series[0].y[k], 1000.0 * p.contour_error[k]);

  const Chart* path = find_chart(doc, "Path in XY");
  ASSERT_NE(path, nullptr);
  EXPECT_TRUE(path->equal_axes);
  const std::size_t at = path->title.find("magnified ");
  ASSERT_NE(at, std::string::npos) << path->title;
  const double factor = std::stod(path->title.substr(at + 10));
  const double mantissa = factor / std::pow(10.0, std::floor(std::log10(factor)));
  EXPECT_TRUE(std::abs(mantissa - 1.0) < 1e-9 || std::abs(mantissa - 2.0) < 1e-9 || std::abs(mantissa - 5.0) < 1e-9);
  double largest = 0.0;
  for (double e : p.contour_error) largest = std::max(largest, std::abs(e));
  EXPECT_LE(factor * largest, 0.1 * 40.0 + 1e-9);  // a tenth of the 40 mm extent
  EXPECT_GT(factor * largest, 0.1 * 40.0 / 2.5);   // the next step would exceed it
  const Series& predicted = path->series.back();
  ASSERT_EQ(predicted.label, "predicted");
  std::size_t on_arc = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    // Steady arc motion (0.6 s to 0.85 s): the nearest path point is on the circle, not on the
    // rapid that leads to it.
    const double t = static_cast<double>(k) * p.ts;
    if (p.kind[k] != motion::PathKind::Arc || t < 0.6 || t > 0.85) continue;
    EXPECT_NEAR(std::hypot(predicted.x[k], predicted.y[k]), 20.0 - factor * p.contour_error[k], 1e-9);
    ++on_arc;
  }
  EXPECT_GT(on_arc, 200u);
}

TEST(PredictionReport, MeasuredColumnsAndScoresAppearWhenMeasured) {
  const vcnc::Prediction p = circle_prediction();
  core::Capture capture;
  capture.ts = p.ts;
  for (std::size_t i = 0; i < p.axes.size(); ++i)
    capture.axes.push_back({motion::axis_name(p.axes[i]), p.command[i], p.predicted[i], {}});
  const vcnc::MeasuredComparison m = vcnc::compare_with_capture(p, capture, "same.csv");
  const Document doc = prediction_report("circle.nc", p, &m);
  const Chart* tracking = find_chart(doc, "Axis x tracking error");
  ASSERT_NE(tracking, nullptr);
  ASSERT_EQ(tracking->series.size(), 2u);
  EXPECT_EQ(tracking->series[0].label, "measured");
  ASSERT_EQ(doc.sections.front().tables.size(), 2u);
  EXPECT_EQ(doc.sections.front().tables[1].rows.size(), m.scores.size());
}

}  // namespace
}  // namespace servotwin::report
