// The fit report: tables carry the fitted numbers, the charts carry the measured points and the
// model, and the measured phase sits on the model's branch. Data: the catalog's E10 two-mass plant
// (0.5 s^2 + 0.06 s + 0.5)/(s^3 + 1.1 s^2 + 9.18 s + 1.8) sampled exactly (closed form), so the fit
// recovers it and the relative error chart is at rounding level.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "report_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/fit/friction_fit.hpp"
#include "servotwin/report/fit_report.hpp"

namespace servotwin::report {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

core::FrequencyResponse e10_response() {
  core::FrequencyResponse r;
  for (int i = 0; i < 40; ++i) {
    const double w = 0.05 * std::pow(200.0, i / 39.0);  // 0.05 .. 10 rad/s
    const std::complex<double> s(0.0, w);
    const std::complex<double> p = (0.5 * s * s + 0.06 * s + 0.5) / (s * s * s + 1.1 * s * s + 9.18 * s + 1.8);
    r.points.push_back({w / kTwoPi, p, 1.0, 0.0, 0.0, 0.0});
  }
  return r;
}

TEST(FitReport, CarriesTheFittedModesAndTheMeasuredPointsOnTheModelsPhaseBranch) {
  const core::FrequencyResponse measured = e10_response();
  const fit::FitReport fitted = fit::fit_plant(measured, {fit::ModelRequest::Kind::kTwoMass, 1});
  const Document doc = fit_report(measured, fitted, "e10.csv");
  const std::string html = testing::render(doc);
  EXPECT_NE(html.find("Two-mass parameters"), std::string::npos);
  // E10: resonance 3 rad/s = 0.477465 Hz, antiresonance 1 rad/s = 0.159155 Hz.
  EXPECT_NE(html.find("0.477465"), std::string::npos);
  EXPECT_NE(html.find("0.159155"), std::string::npos);
  ASSERT_EQ(chart_count(doc), 3u);

  const Section& response = doc.sections.back();
  const Chart& phase = response.charts[1];
  ASSERT_EQ(phase.series.size(), 2u);
  const Series& measured_phase = phase.series[0];
  const Series& model_phase = phase.series[1];
  for (std::size_t i = 0; i < measured_phase.x.size(); ++i) {
    // The model's dense-grid phase at the nearest grid frequency (within 0.5 % in frequency).
    std::size_t j = 0;
    while (j + 1 < model_phase.x.size() && model_phase.x[j] < measured_phase.x[i]) ++j;
    EXPECT_NEAR(measured_phase.y[i], model_phase.y[j], 5.0) << "point " << i;
  }
  for (double e : response.charts[2].series[0].y) EXPECT_LT(e, 1e-6);
}

TEST(FitReport, ListsThePointsLeftOutAndWhy) {
  core::FrequencyResponse measured = e10_response();
  measured.points[3].valid = false;
  measured.points[3].note = "THD 0.39 above 0.07 at amplitude 2.4";
  const fit::FitReport fitted = fit::fit_plant(measured, {fit::ModelRequest::Kind::kTwoMass, 1});
  ASSERT_EQ(fitted.left_out.size(), 1u);
  const std::string html = testing::render(fit_report(measured, fitted, "e10.csv"));
  EXPECT_NE(html.find("Points left out (marked invalid by the measurement, or outliers of the first fit)"), std::string::npos);
  EXPECT_NE(html.find("THD 0.39 above 0.07 at amplitude 2.4"), std::string::npos);
}

TEST(FitReport, WithFrictionDrawsTheModelWithFrictionAndItsLinearPart) {
  // A swept-sine response (each point with its amplitude) of the motor bench's two-mass chain
  // without friction (the chain's own equations, fit::coulomb_two_mass_response at zero levels):
  // the friction fit finds none, so the model with friction at each point equals the data to the
  // fit's accuracy, and the report draws it beside the linear part and says what was fitted.
  core::FrequencyResponse measured;
  measured.quality_kind = core::QualityKind::kThd;
  for (double f : core::log_space(1.0, 300.0, 40)) {
    core::FrequencyPoint p;
    p.freq_hz = f;
    p.value = fit::coulomb_two_mass_response(kTwoPi * f, 1.0, 0.0048146, 0.0050854, 563.95, 0.06774, 3e-4, 0.0, 0.0, {});
    p.amplitude = 2.0;
    measured.points.push_back(p);
  }
  const fit::FitReport linear = fit::fit_plant(measured, {fit::ModelRequest::Kind::kTwoMass, 1});
  const fit::CoulombFit friction = fit::fit_coulomb_friction(measured, linear, {});
  ASSERT_TRUE(friction.fitted) << friction.note;
  const fit::FitReport written = fit::with_friction_model(linear, friction);
  const Document doc = fit_report(measured, written, "e10.csv", nullptr, &friction);
  const std::string html = testing::render(doc);
  EXPECT_NE(html.find("Coulomb friction"), std::string::npos);
  EXPECT_NE(html.find("load Coulomb friction Ml"), std::string::npos);
  const Section& response = doc.sections.back();
  ASSERT_EQ(response.charts[0].series.size(), 3u);
  EXPECT_EQ(response.charts[0].series[1].label, "linear part");
  EXPECT_EQ(response.charts[0].series[2].label, "with Coulomb friction");
  EXPECT_EQ(response.charts[0].series[2].x.size(), measured.points.size());
  for (double e : response.charts[2].series[0].y) EXPECT_LT(e, 1e-6);
}

TEST(FitReport, AnEmptyResponseIsAnInputError) {
  EXPECT_THROW((void)fit_report({}, fit::FitReport{}, "x.csv"), core::InputError);
}

}  // namespace
}  // namespace servotwin::report
