// Residual vibration, sensitivity curves, insensitivity bandwidth, smoothing and comparisons.
// Expected values: closed forms (undamped ZV: V = |cos(πω/(2ω_n))|), Klipper's published
// calibrate_shaper output ("mzv 34.6 Hz ... smoothing ~= 0.170", docs/Measuring_Resonances.md
// style output with damping 0.1, accel 5000, scv 5), and tests/data/shaping/{smoothing,
// bandwidth}.json from tools/reference/shaping_reference.py.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/smoothing.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::shaping {
namespace {

using std::numbers::pi;

TEST(ResidualVibration, UndampedZvClosedForm) {
  const Shaper zv = zv_shaper(1.0, 0.0);
  for (double w : {0.0, 0.3, 0.9, 1.0, 1.7, 3.0})
    EXPECT_NEAR(residual_vibration(zv, w, 0.0), std::abs(std::cos(pi * w / 2.0)), 1e-15) << w;
}

TEST(ResidualVibration, SingleImpulseIsOneAndDampingOfAModeError) {
  Shaper unit{"unit", 1.0, 0.0, {0.0}, {1.0}};
  EXPECT_DOUBLE_EQ(residual_vibration(unit, 5.0, 0.3), 1.0);
  // Unnormalized amplitudes are normalized by ΣA (Klipper's 1/ΣA).
  Shaper twice{"zv", 1.0, 0.0, {0.0, pi}, {2.0, 2.0}};
  EXPECT_NEAR(residual_vibration(twice, 0.5, 0.0), std::cos(pi / 4.0), 1e-15);
  // Damped ZV designed for ζ=0.1 evaluated on a mode with ζ=0: closed form |A1 + A2 e^{jπ/√(1−ζ²)}|.
  const Shaper zv = zv_shaper(1.0, 0.1);
  const double phase = pi / std::sqrt(1.0 - 0.01);
  EXPECT_NEAR(residual_vibration(zv, 1.0, 0.0),
              std::hypot(zv.amplitudes[0] + zv.amplitudes[1] * std::cos(phase), zv.amplitudes[1] * std::sin(phase)), 1e-15);
  EXPECT_NEAR(damping_sensitivity(zv, {0.0, 0.1})[0], residual_vibration(zv, 1.0, 0.0), 0.0);
  EXPECT_LT(damping_sensitivity(zv, {0.0, 0.1})[1], 1e-15);
}

TEST(ResidualVibration, NoOverflowForLongShapers) {
  Shaper longer = zvd_shaper(1.0, 0.9);
  longer.times = {0.0, 500.0, 1000.0};
  EXPECT_TRUE(std::isfinite(residual_vibration(longer, 3.0, 0.9)));
}

TEST(ResidualVibration, RejectsBadArguments) {
  const Shaper zv = zv_shaper(1.0, 0.0);
  EXPECT_THROW((void)residual_vibration(zv, -1.0, 0.0), core::InputError);
  EXPECT_THROW((void)residual_vibration(zv, 1.0, 1.0), core::InputError);
  EXPECT_THROW((void)residual_vibration(Shaper{}, 1.0, 0.0), core::InputError);
}

TEST(SensitivityCurve, EndpointsAndValues) {
  const Shaper zvd = zvd_shaper(1.0, 0.0);
  const auto curve = sensitivity_curve(zvd, 0.0, 2.0, 201, 0.0);
  ASSERT_EQ(curve.size(), 201u);
  EXPECT_DOUBLE_EQ(curve.front().omega, 0.0);
  EXPECT_DOUBLE_EQ(curve.back().omega, 2.0);
  for (const auto& p : curve) EXPECT_NEAR(p.vibration, std::pow(std::cos(pi * p.omega / 2.0), 2), 1e-14);
  EXPECT_THROW((void)sensitivity_curve(zvd, 1.0, 1.0, 10, 0.0), core::InputError);
}

TEST(InsensitivityBand, UndampedZvClosedForm) {
  // |cos(πω/2)| ≤ V  ⇔  ω ∈ [2/π acos V, 2 − 2/π acos V].
  const Shaper zv = zv_shaper(1.0, 0.0);
  const InsensitiveBand band = insensitivity_band(zv, 0.05, 0.0);
  const double low = 2.0 / pi * std::acos(0.05);
  EXPECT_NEAR(band.omega_low, low, 1e-9);
  EXPECT_NEAR(band.omega_high, 2.0 - low, 1e-9);
  EXPECT_NEAR(band.normalized_width, 2.0 - 2.0 * low, 2e-9);
}

TEST(InsensitivityBand, MatchesReference) {
  const nlohmann::json data = test::load_fixture("bandwidth.json");
  for (const auto& c : data.at("cases")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Shaper s = test::shaper_from(c, c.at("omega"), c.at("zeta"));
    const InsensitiveBand band = insensitivity_band(s, c.at("level"), c.at("zeta"));
    EXPECT_NEAR(band.omega_low, c.at("omega_low").get<double>(), 1e-9);
    EXPECT_NEAR(band.omega_high, c.at("omega_high").get<double>(), 1e-9);
  }
  // The EI family is wider than ZV at 5 % (that is its purpose).
  EXPECT_GT(insensitivity_band(ei_shaper(1.0, 0.0), 0.05, 0.0).normalized_width,
            insensitivity_band(zv_shaper(1.0, 0.0), 0.05, 0.0).normalized_width);
  EXPECT_THROW((void)insensitivity_band(zv_shaper(1.0, 0.0), 1.5, 0.0), core::InputError);
}

TEST(Smoothing, KlipperPublishedOutput) {
  // Klipper's calibrate_shaper prints "Fitted shaper 'mzv' frequency = 34.6 Hz (vibrations = 0.0%,
  // smoothing ~= 0.170)" (docs/Measuring_Resonances.md; damping 0.1, accel 5000 mm/s², scv 5 mm/s).
  EXPECT_NEAR(shaper_smoothing(mzv_shaper(2.0 * pi * 34.6, 0.1)), 0.170, 5e-4);
}

TEST(Smoothing, MatchesTrajectoryReference) {
  const nlohmann::json data = test::load_fixture("smoothing.json");
  for (const auto& c : data.at("cases")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const SmoothingOffsets o = smoothing_offsets(test::shaper_from(c), c.at("accel"), c.at("scv"));
    const double scale = c.at("smoothing").get<double>();
    EXPECT_NEAR(o.corner_90, c.at("corner_90").get<double>(), 1e-12 * scale);
    EXPECT_NEAR(o.reversal_180, c.at("reversal_180").get<double>(), 1e-12 * scale);
  }
}

TEST(Smoothing, MaxAccelInvertsTheMeasure) {
  const Shaper mzv = mzv_shaper(2.0 * pi * 50.0, 0.1);
  const double accel = max_accel_for_smoothing(mzv, 0.12, 5.0);
  EXPECT_NEAR(shaper_smoothing(mzv, accel, 5.0), 0.12, 1e-9);
  EXPECT_THROW((void)max_accel_for_smoothing(mzv, 1e-6, 5.0), core::InputError);
  EXPECT_THROW((void)smoothing_offsets(mzv, -1.0, 5.0), core::InputError);
}

// The selection and the comparison report both ask "largest acceleration, or none": one function
// answers, nullopt exactly where max_accel_for_smoothing refuses.
TEST(Smoothing, ReachableMaxAccelIsNoneExactlyWhenTheCornerAloneSmoothsMore) {
  const Shaper mzv = mzv_shaper(2.0 * pi * 50.0, 0.1);
  EXPECT_EQ(reachable_max_accel(mzv, 0.12, 5.0), max_accel_for_smoothing(mzv, 0.12, 5.0));
  const double at_rest = shaper_smoothing(mzv, 0.0, 5.0);
  EXPECT_FALSE(reachable_max_accel(mzv, 0.99 * at_rest, 5.0).has_value());
  EXPECT_TRUE(reachable_max_accel(mzv, 1.01 * at_rest, 5.0).has_value());
  EXPECT_EQ(reachable_max_accel(Shaper{"single", 1.0, 0.0, {0.0}, {1.0}}, 0.12, 5.0), std::numeric_limits<double>::infinity());
  EXPECT_THROW((void)reachable_max_accel(mzv, 0.0, 5.0), core::InputError);
}

TEST(Compare, RowsCarryEveryMeasure) {
  const std::vector<Shaper> set = {zv_shaper(10.0, 0.05), mzv_shaper(10.0, 0.05), ei_shaper(10.0, 0.05),
                                   zv4_shaper(10.0, 0.05, {0.3, 0.5, 0.0})};
  const auto rows = compare_shapers(set);
  ASSERT_EQ(rows.size(), set.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].type, set[i].type);
    EXPECT_DOUBLE_EQ(rows[i].duration_s, set[i].duration());
    EXPECT_DOUBLE_EQ(rows[i].smoothing, shaper_smoothing(set[i]));
    const InsensitiveBand band = insensitivity_band(set[i], 0.05, 0.05);
    EXPECT_DOUBLE_EQ(rows[i].band_width_normalized, band.normalized_width);
    EXPECT_EQ(rows[i].impulse_count, static_cast<int>(set[i].times.size()));
  }
  EXPECT_NEAR(rows[2].residual_at_design, 0.05, 1e-12);
  EXPECT_LT(rows[0].duration_s, rows[1].duration_s);
}

}  // namespace
}  // namespace servotwin::shaping
