// The shaper comparison report: the table carries exactly shaping::compare_shapers' numbers (and
// shaping::max_accel_for_smoothing's), and the charts carry the residual vibration of each shaper
// checked against closed forms written out here: for a two-impulse ZV shaper A1 δ(t) + A2 δ(t − t2)
// on a mode (ω, ζ), V = |A1 e^{−ζω t2} + A2 e^{j ω √(1−ζ²) t2}| / (A1 + A2) (catalog C6.3), which for
// ζ = 0 is |cos(π f / (2 f0))|.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include "report_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/report/shaper_report.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/smoothing.hpp"

namespace servotwin::report {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace shaper_report_test {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// V of a two-impulse shaper (times 0 and t2) on the mode (omega, zeta), from the definition.
double two_impulse_vibration(const shaping::Shaper& s, double omega, double zeta) {
  const double t2 = s.times.at(1);
  const std::complex<double> sum = s.amplitudes[0] * std::exp(-zeta * omega * t2) +
                                   s.amplitudes[1] * std::polar(1.0, omega * std::sqrt(1.0 - zeta * zeta) * t2);
  return std::abs(sum) / (s.amplitudes[0] + s.amplitudes[1]);
}

std::vector<NamedShaper> klipper_set() {
  const double w = kTwoPi * 40.0;
  return {{"zv.json", shaping::zv_shaper(w, 0.1)},
          {"mzv.json", shaping::mzv_shaper(w, 0.1)},
          {"ei.json", shaping::ei_shaper(w, 0.1)},
          {"2hump.json", shaping::two_hump_ei_shaper(kTwoPi * 25.0, 0.05)},
          {"zvd.json", shaping::zvd_shaper(kTwoPi * 55.0, 0.0)}};
}

const Chart& chart_titled(const Document& doc, const std::string& prefix) {
  for (const auto& s : doc.sections)
    for (const auto& c : s.charts)
      if (c.title.rfind(prefix, 0) == 0) return c;
  throw std::runtime_error("no chart " + prefix);
}

TEST(ShaperReport, TableNumbersAreCompareShapersRows) {
  const std::vector<NamedShaper> set = klipper_set();
  ShaperReportOptions options;
  options.comparison = {0.07, 3000.0, 4.0};
  options.max_smoothing = 0.1;
  const std::vector<ShaperComparison> rows = shaper_comparison(set, options);
  std::vector<shaping::Shaper> plain;
  for (const auto& s : set) plain.push_back(s.shaper);
  const std::vector<shaping::ShaperComparisonRow> expected = shaping::compare_shapers(plain, options.comparison);
  ASSERT_EQ(rows.size(), set.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE(set[i].name);
    EXPECT_EQ(rows[i].name, set[i].name);
    EXPECT_EQ(rows[i].row.type, expected[i].type);
    EXPECT_EQ(rows[i].row.duration_s, expected[i].duration_s);
    EXPECT_EQ(rows[i].row.residual_at_design, expected[i].residual_at_design);
    EXPECT_EQ(rows[i].row.band_width_normalized, expected[i].band_width_normalized);
    EXPECT_EQ(rows[i].row.band_low_ratio, expected[i].band_low_ratio);
    EXPECT_EQ(rows[i].row.band_high_ratio, expected[i].band_high_ratio);
    EXPECT_EQ(rows[i].row.smoothing, expected[i].smoothing);
    EXPECT_EQ(rows[i].row.impulse_count, expected[i].impulse_count);
    EXPECT_DOUBLE_EQ(rows[i].freq_hz * kTwoPi, set[i].shaper.omega);
    EXPECT_EQ(rows[i].zeta, set[i].shaper.zeta);
    EXPECT_EQ(rows[i].max_accel, shaping::max_accel_for_smoothing(set[i].shaper, 0.1, 4.0));
  }

  // The document's table shows those numbers, one row per shaper in order.
  const Document doc = shaper_report(set, options);
  const Table& table = doc.sections.at(0).tables.at(0);
  ASSERT_EQ(table.rows.size(), set.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& cells = table.rows[i];
    ASSERT_EQ(cells.size(), table.header.size());
    EXPECT_EQ(cells[0], set[i].name);
    EXPECT_EQ(cells[4], std::to_string(expected[i].impulse_count));
    EXPECT_NEAR(std::stod(cells[5]), expected[i].duration_s, 1e-4 * expected[i].duration_s);
    EXPECT_NEAR(std::stod(cells[9]), expected[i].smoothing, 1e-3 * expected[i].smoothing);
    EXPECT_NEAR(std::stod(cells[10]), rows[i].max_accel, 1e-4 * rows[i].max_accel);
  }
  EXPECT_NE(table.header[7].find("7 %"), std::string::npos);
}

TEST(ShaperReport, FrequencyCurvesAreTheResidualVibrationOnOneHzAxis) {
  const std::vector<NamedShaper> set = klipper_set();
  const Document doc = shaper_report(set);
  const Chart& chart = chart_titled(doc, "Residual vibration versus mode frequency");
  ASSERT_EQ(chart.series.size(), set.size() + 1);
  for (std::size_t i = 0; i < set.size(); ++i) {
    const Series& s = chart.series[i];
    SCOPED_TRACE(s.label);
    ASSERT_GE(s.x.size(), 1001u);
    EXPECT_EQ(s.x.front(), 0.0);
    EXPECT_NEAR(s.x.back(), 2.5 * 55.0, 1e-9);  // 2.5 x the highest design frequency
    EXPECT_TRUE(std::is_sorted(s.x.begin(), s.x.end()));
    for (std::size_t k = 0; k < s.x.size(); ++k)
      EXPECT_NEAR(s.y[k], 100.0 * shaping::residual_vibration(set[i].shaper, kTwoPi * s.x[k], set[i].shaper.zeta), 1e-12);
    // Each shaper's own design frequency is a point of the curve.
    const double f0 = set[i].shaper.omega / kTwoPi;
    EXPECT_TRUE(std::any_of(s.x.begin(), s.x.end(), [&](double f) { return std::abs(f - f0) < 1e-9 * f0; }));
  }
  // The ZV curve against the closed form: 0 at 40 Hz, rising on both sides.
  const Series& zv = chart.series[0];
  const auto at40 = static_cast<std::size_t>(std::find_if(zv.x.begin(), zv.x.end(), [](double f) { return std::abs(f - 40.0) < 1e-9; }) - zv.x.begin());
  ASSERT_LT(at40, zv.x.size());
  for (std::size_t k = 0; k < zv.x.size(); ++k)
    EXPECT_NEAR(zv.y[k], 100.0 * two_impulse_vibration(set[0].shaper, kTwoPi * zv.x[k], 0.1), 1e-10) << zv.x[k];
  EXPECT_LT(zv.y[at40], 1e-12);
  for (std::size_t k = at40 + 1; k < zv.x.size() && zv.x[k] < 60.0; ++k) EXPECT_GT(zv.y[k], zv.y[k - 1]);
  for (std::size_t k = at40; k > 0 && zv.x[k - 1] > 25.0; --k) EXPECT_GT(zv.y[k - 1], zv.y[k]);
  EXPECT_NEAR(zv.y.front(), 100.0, 1e-9);  // a mode at 0 Hz is not reduced
  // The level line spans the axis at 5 %.
  const Series& level = chart.series.back();
  EXPECT_EQ(level.x, (std::vector<double>{0.0, 2.5 * 55.0}));
  EXPECT_EQ(level.y, (std::vector<double>{5.0, 5.0}));
}

TEST(ShaperReport, UndampedZvCurveIsTheCosineAndTheBandEdgesAreOnIt) {
  const std::vector<NamedShaper> set = {{"zv", shaping::zv_shaper(kTwoPi * 10.0, 0.0)}};
  ShaperReportOptions options;
  options.freq_min_hz = 5.0;
  options.freq_max_hz = 15.0;
  options.curve_points = 101;
  const Document doc = shaper_report(set, options);
  const Chart& chart = chart_titled(doc, "Residual vibration versus mode frequency");
  const Series& s = chart.series[0];
  EXPECT_EQ(s.x.front(), 5.0);
  EXPECT_EQ(s.x.back(), 15.0);
  for (std::size_t k = 0; k < s.x.size(); ++k)
    EXPECT_NEAR(s.y[k], 100.0 * std::abs(std::cos(std::numbers::pi * s.x[k] / 20.0)), 1e-10);
  // Band edges where |cos(π f / 20)| = 0.05: f = 20 acos(±0.05)/π; they are points of the curve.
  for (double edge : {20.0 * std::acos(0.05) / std::numbers::pi, 20.0 * std::acos(-0.05) / std::numbers::pi}) {
    const auto it = std::min_element(s.x.begin(), s.x.end(), [&](double a, double b) { return std::abs(a - edge) < std::abs(b - edge); });
    EXPECT_NEAR(*it, edge, 1e-8);
    EXPECT_NEAR(s.y[static_cast<std::size_t>(it - s.x.begin())], 5.0, 1e-6);
  }
}

TEST(ShaperReport, DampingCurveIsTheVibrationAtTheDesignFrequency) {
  const std::vector<NamedShaper> set = {{"zv", shaping::zv_shaper(kTwoPi * 30.0, 0.0)},
                                        {"zvd", shaping::zvd_shaper(kTwoPi * 30.0, 0.15)}};
  const Document doc = shaper_report(set);
  const Chart& chart = chart_titled(doc, "Residual vibration at the design frequency versus mode damping");
  ASSERT_EQ(chart.series.size(), 2u);
  const Series& zv = chart.series[0];
  EXPECT_EQ(zv.x.front(), 0.0);
  EXPECT_NEAR(zv.x.back(), 0.3, 1e-15);  // 2 x the highest design damping
  EXPECT_NEAR(zv.y.front(), 0.0, 1e-12);
  for (std::size_t k = 0; k < zv.x.size(); ++k)
    EXPECT_NEAR(zv.y[k], 100.0 * two_impulse_vibration(set[0].shaper, set[0].shaper.omega, zv.x[k]), 1e-10);
  const Series& zvd = chart.series[1];
  const auto design = std::find(zvd.x.begin(), zvd.x.end(), 0.15);
  ASSERT_NE(design, zvd.x.end());
  EXPECT_LT(zvd.y[static_cast<std::size_t>(design - zvd.x.begin())], 1e-10);
  for (std::size_t k = 0; k < zvd.x.size(); ++k)
    EXPECT_NEAR(zvd.y[k], 100.0 * shaping::residual_vibration(set[1].shaper, set[1].shaper.omega, zvd.x[k]), 1e-12);
}

TEST(ShaperReport, ImpulseSpikesAndStaircaseStepShowTheImpulses) {
  const std::vector<NamedShaper> set = klipper_set();
  const Document doc = shaper_report(set);
  const Chart& impulses = chart_titled(doc, "Impulse trains");
  const Chart& steps = chart_titled(doc, "Shaped unit step");
  ASSERT_EQ(impulses.series.size(), set.size());
  ASSERT_EQ(steps.series.size(), set.size() + 1);
  double longest = 0.0;
  for (const auto& s : set) longest = std::max(longest, s.shaper.duration());
  for (std::size_t i = 0; i < set.size(); ++i) {
    const shaping::Shaper& sh = set[i].shaper;
    SCOPED_TRACE(set[i].name);
    const Series& spikes = impulses.series[i];
    ASSERT_EQ(spikes.x.size(), 3 * sh.times.size());
    EXPECT_TRUE(std::is_sorted(spikes.x.begin(), spikes.x.end()));
    for (std::size_t k = 0; k < sh.times.size(); ++k) {
      EXPECT_EQ(spikes.x[3 * k + 1], sh.times[k]);
      EXPECT_EQ(spikes.y[3 * k + 1], sh.amplitudes[k]);
      EXPECT_EQ(spikes.y[3 * k], 0.0);
      EXPECT_EQ(spikes.y[3 * k + 2], 0.0);
      EXPECT_LE(spikes.x[3 * k + 2] - spikes.x[3 * k], 6.001e-3 * longest);
    }
    // The staircase: the partial sums of the amplitudes at the impulse times, 0 before, 1 after.
    const Series& step = steps.series[i + 1];
    EXPECT_TRUE(std::is_sorted(step.x.begin(), step.x.end()));
    EXPECT_EQ(step.y.front(), 0.0);
    EXPECT_NEAR(step.y.back(), 1.0, 1e-12);
    EXPECT_NEAR(step.x.back(), 1.2 * longest, 1e-15);
    double sum = 0.0;
    for (std::size_t k = 0; k < sh.times.size(); ++k) {
      const auto at = std::find(step.x.begin(), step.x.end(), sh.times[k]);
      ASSERT_NE(at, step.x.end());
      const auto j = static_cast<std::size_t>(at - step.x.begin());
      EXPECT_NEAR(step.y[j - 1], sum, 1e-15);  // just before the impulse
      sum += sh.amplitudes[k];
      EXPECT_NEAR(step.y[j], sum, 1e-15);
    }
    // The value reaches 1 exactly at the shaper's duration: the delay.
    const auto last = std::find(step.x.begin(), step.x.end(), sh.duration());
    EXPECT_NEAR(step.y[static_cast<std::size_t>(last - step.x.begin()) - 1], 1.0 - sh.amplitudes.back(), 1e-12);
  }
  EXPECT_EQ(steps.series[0].label, "unshaped step");
}

TEST(ShaperReport, WritesHtmlWithEveryChartsData) {
  const std::vector<NamedShaper> set = klipper_set();
  const Document doc = shaper_report(set);
  EXPECT_EQ(chart_count(doc), 4u);
  const std::string html = testing::render(doc);
  const nlohmann::json data = testing::chart_data(html);
  ASSERT_EQ(data.at("charts").size(), 4u);
  for (const auto& chart : data.at("charts")) {
    for (const auto& series : chart.at("series")) {
      // Nothing decimated: every sample is drawn.
      EXPECT_EQ(series.at("x").size(), series.at("samples").get<std::size_t>()) << chart.at("title");
      EXPECT_GE(series.at("x").size(), 2u);
    }
  }
  for (const auto& s : set) EXPECT_NE(html.find(s.name), std::string::npos);
  EXPECT_NE(html.find("Sensitivity to damping"), std::string::npos);
}

TEST(ShaperReport, MaxAccelMarksUnlimitedAndImpossible) {
  shaping::Shaper single{"none", kTwoPi * 20.0, 0.0, {0.0}, {1.0}};
  // A 0.67 Hz crane shaper smooths far more than 0.12 mm at scv 5 mm/s alone.
  const std::vector<NamedShaper> set = {{"single", single}, {"crane", shaping::zv_shaper(kTwoPi * 0.67, 0.0079)}};
  const std::vector<ShaperComparison> rows = shaper_comparison(set);
  EXPECT_TRUE(std::isinf(rows[0].max_accel));
  EXPECT_TRUE(std::isnan(rows[1].max_accel));
  const Document doc = shaper_report(set);
  EXPECT_EQ(doc.sections[0].tables[0].rows[0].back(), "unlimited");
  EXPECT_EQ(doc.sections[0].tables[0].rows[1].back(), "none");
  EXPECT_NEAR(chart_titled(doc, "Shaped unit step").series[1].x.back(), 1.2 * set[1].shaper.duration(), 1e-12);
  // A single impulse alone has no time span: the time charts show half a period of 20 Hz.
  const Document alone = shaper_report({set[0]});
  EXPECT_NEAR(chart_titled(alone, "Shaped unit step").series[1].x.back(), 1.2 * 0.025, 1e-12);
  EXPECT_NEAR(chart_titled(alone, "Impulse trains").series[0].y[1], 1.0, 0.0);
}

TEST(ShaperReport, BadInputIsNamed) {
  const auto expect_field = [](auto&& call, const std::string& field) {
    try {
      call();
      ADD_FAILURE() << "no error for " << field;
    } catch (const core::InputError& e) {
      EXPECT_EQ(e.where().field, field) << e.what();
    }
  };
  expect_field([] { (void)shaper_report({}); }, "shapers");
  const std::vector<NamedShaper> one = {{"zv", shaping::zv_shaper(kTwoPi * 10.0, 0.1)}};
  ShaperReportOptions o;
  o.freq_max_hz = 0.0;
  expect_field([&] { (void)shaper_report(one, o); }, "freq_max_hz");
  o = {};
  o.freq_min_hz = -1.0;
  expect_field([&] { (void)shaper_report(one, o); }, "freq_min_hz");
  o = {};
  o.curve_points = 1;
  expect_field([&] { (void)shaper_report(one, o); }, "curve_points");
  o = {};
  o.max_smoothing = 0.0;
  expect_field([&] { (void)shaper_report(one, o); }, "max_smoothing");
  o = {};
  o.comparison.level = 1.5;
  expect_field([&] { (void)shaper_report(one, o); }, "level");
  std::vector<NamedShaper> bad = one;
  bad[0].shaper.omega = 0.0;
  expect_field([&] { (void)shaper_report(bad); }, "shapers[0]");
  bad = one;
  bad[0].shaper.amplitudes.pop_back();
  expect_field([&] { (void)shaper_comparison(bad); }, "shapers[0]");
}

}  // namespace shaper_report_test
}  // namespace
}  // namespace servotwin::report
