// Starting values: three-point interpolation (catalog C5.8, example E10b) and peak picking.
#include <gtest/gtest.h>

#include <cmath>

#include "fit_test_support.hpp"
#include "servotwin/fit/initialization.hpp"

namespace servotwin::fit::test {
namespace {

// E10b: exact points of num = [0.5, 0.06, 0.5], den = [1, 1.1, 9.18, 1.8] at ω = 0.1, 1, 3 give
// the coefficients back exactly (catalog E10b, derived there from the printed Table 5.1 plant).
TEST(ThreePointInterpolation, E10bRecoversTheCoefficientsExactly) {
  const core::TransferFunction tf(core::Polynomial{0.5, 0.06, 0.5}, core::Polynomial{1.0, 1.1, 9.18, 1.8});
  const std::array<double, 3> w{0.1, 1.0, 3.0};
  std::array<std::complex<double>, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) v[i] = tf.frequency_response(w[i]);
  const InterpolationResult r = three_point_interpolation(w, v);
  ASSERT_TRUE(r.model) << r.failure;
  const std::array<double, 3> num{0.5, 0.06, 0.5};
  const std::array<double, 4> den{1.0, 1.1, 9.18, 1.8};
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(r.numerator[i], num[i], 1e-13) << i;
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(r.denominator[i], den[i], 1e-13) << i;
  // Back-out (E10b): K = 0.5, ωz = 1, ζz = 0.06; cubic roots −0.2 and −0.45 ± 2.966j (ωn 3, ζn 0.15).
  const PlantModel& m = *r.model;
  EXPECT_NEAR(m.gain, 0.5, 1e-13);
  EXPECT_NEAR(m.rigid_pole_rad_s, 0.2, 1e-13);
  EXPECT_NEAR(m.modes[0].antiresonance.omega_rad_s, 1.0, 1e-13);
  EXPECT_NEAR(m.modes[0].antiresonance.zeta, 0.06, 1e-13);
  EXPECT_NEAR(m.modes[0].resonance.omega_rad_s, 3.0, 1e-13);
  EXPECT_NEAR(m.modes[0].resonance.zeta, 0.15, 1e-13);
}

TEST(ThreePointInterpolation, IntegratorClassFixesA0AtZero) {
  PlantModel truth = e10_plant();
  truth.rigid = RigidKind::kIntegrator;
  const std::array<double, 3> w{0.2, 1.0, 3.0};
  std::array<std::complex<double>, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) v[i] = truth.transfer_function().frequency_response(w[i]);
  const InterpolationResult r = three_point_interpolation(w, v, RigidKind::kIntegrator);
  ASSERT_TRUE(r.model) << r.failure;
  EXPECT_EQ(r.denominator[3], 0.0);
  EXPECT_NEAR(r.model->gain, 0.5, 1e-12);
  EXPECT_NEAR(r.model->modes[0].resonance.omega_rad_s, 3.0, 1e-12);
  EXPECT_NEAR(r.model->modes[0].antiresonance.zeta, 0.06, 1e-12);
}

TEST(ThreePointInterpolation, UnitsOfTheDataOnlyScaleTheGain) {
  const PlantModel truth = e10_plant();
  const std::array<double, 3> w{0.1, 1.0, 3.0};
  std::array<std::complex<double>, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) v[i] = 1000.0 * truth.response(w[i]);  // mm instead of m
  const InterpolationResult r = three_point_interpolation(w, v);
  ASSERT_TRUE(r.model);
  EXPECT_NEAR(r.model->gain, 500.0, 1e-9);
  EXPECT_NEAR(r.model->modes[0].resonance.zeta, 0.15, 1e-12);
}

TEST(ThreePointInterpolation, NoResonanceIsReported) {
  // A rigid plant with a lag has no complex pole pair: the solve works but the back-out must say so.
  const core::TransferFunction tf(core::Polynomial{1.0, 3.0, 2.0}, core::Polynomial{1.0, 6.0, 11.0, 6.0});
  const std::array<double, 3> w{0.1, 1.0, 10.0};
  std::array<std::complex<double>, 3> v{};
  for (std::size_t i = 0; i < 3; ++i) v[i] = tf.frequency_response(w[i]);
  const InterpolationResult r = three_point_interpolation(w, v);
  EXPECT_FALSE(r.model);
  EXPECT_FALSE(r.failure.empty());
  EXPECT_THROW(three_point_interpolation({1.0, 1.0, 2.0}, v), std::invalid_argument);
}

TEST(InterpolationPoints, AutomaticChoiceIsLowAntiresonanceResonance) {
  const core::FrequencyResponse r = sample(e10_plant(), 0.05, 15.0, 40);
  const auto idx = choose_interpolation_points(r, OutputKind::kVelocity);
  ASSERT_TRUE(idx);
  EXPECT_EQ((*idx)[0], 0u);
  // The measured points nearest to the magnitude minimum (≈ ωz = 1) and maximum (≈ ωn = 3).
  EXPECT_NEAR(kTwoPi * r.points[(*idx)[1]].freq_hz, 1.0, 0.12);
  EXPECT_NEAR(kTwoPi * r.points[(*idx)[2]].freq_hz, 3.0, 0.4);
}

TEST(PeakPicking, FindsBothTestBedModesAndTheirDamping) {
  const core::FrequencyResponse r = sample(e37_plant(1), 1e-3, 2000.0, 120);
  const PeakPicking p = pick_peaks(r, OutputKind::kVelocity);
  ASSERT_EQ(p.resonances.size(), 2u);  // the rigid/lag hump is not a mode
  const ModePairing pairs = pair_modes(p, 2);
  ASSERT_EQ(pairs.pairs.size(), 2u) << pairs.failure;
  // Parabolic refinement on a grid with 8 % spacing: frequencies within a few per cent.
  EXPECT_NEAR(pairs.pairs[0].first.omega_rad_s, 35.3, 0.05 * 35.3);
  EXPECT_NEAR(pairs.pairs[0].second.omega_rad_s, 70.8, 0.05 * 70.8);
  EXPECT_NEAR(pairs.pairs[1].first.omega_rad_s, 114.6, 0.05 * 114.6);
  EXPECT_NEAR(pairs.pairs[1].second.omega_rad_s, 260.1, 0.05 * 260.1);
  // Damping: right order of magnitude (a start, not an estimate).
  EXPECT_LT(pairs.pairs[0].second.zeta, 0.1);
  EXPECT_GT(pairs.pairs[0].first.zeta, 0.05);
  EXPECT_EQ(pair_modes(p, 3).pairs.size(), 0u);
  EXPECT_FALSE(pair_modes(p, 3).failure.empty());
}

}  // namespace
}  // namespace servotwin::fit::test
