// Plant model classes (fit/plant_model.hpp). Expected responses and polynomials come from
// scipy.signal.freqs / numpy.polymul in tools/reference/fit_reference.py (fit_reference.json).
#include <gtest/gtest.h>

#include <cmath>

#include "fit_test_support.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit::test {
namespace {

PlantModel model_from_fixture(const nlohmann::json& j) {
  PlantModel m;
  m.gain = j["gain"].get<double>();
  m.rigid_pole_rad_s = j["rigid_pole"].get<double>();
  for (const auto& mode : j["modes"])
    m.modes.push_back(Mode{{mode["wz"].get<double>(), mode["zeta_z"].get<double>()},
                           {mode["wp"].get<double>(), mode["zeta_p"].get<double>()}});
  if (!j["lag_pole"].is_null()) m.lag_pole_rad_s = j["lag_pole"].get<double>();
  m.output = j["output"] == "position" ? OutputKind::kPosition : OutputKind::kVelocity;
  return m;
}

class PlantModelReference : public ::testing::TestWithParam<std::string> {};

TEST_P(PlantModelReference, ResponseAndPolynomialsMatchScipy) {
  const auto& j = fixture_model(GetParam());
  const PlantModel m = model_from_fixture(j);
  const auto w = j["omega"].get<std::vector<double>>();
  const auto re = j["re"].get<std::vector<double>>();
  const auto im = j["im"].get<std::vector<double>>();
  const core::TransferFunction tf = m.transfer_function();
  for (std::size_t i = 0; i < w.size(); ++i) {
    const std::complex<double> expected(re[i], im[i]);
    EXPECT_LT(std::abs(m.response(w[i]) - expected), 1e-10 * std::abs(expected)) << "omega " << w[i];
    EXPECT_LT(std::abs(tf.frequency_response(w[i]) - expected), 1e-9 * std::abs(expected)) << "omega " << w[i];
  }
  const auto num = j["numerator"].get<std::vector<double>>();
  const auto den = j["denominator"].get<std::vector<double>>();
  ASSERT_EQ(tf.num().coefficients().size(), num.size());
  ASSERT_EQ(tf.den().coefficients().size(), den.size());
  for (std::size_t i = 0; i < num.size(); ++i) EXPECT_NEAR(tf.num().coefficients()[i], num[i], 1e-12 * std::abs(num[i]));
  for (std::size_t i = 0; i < den.size(); ++i) EXPECT_NEAR(tf.den().coefficients()[i], den[i], 1e-12 * std::abs(den[i]) + 1e-300);
}

INSTANTIATE_TEST_SUITE_P(Catalog, PlantModelReference, ::testing::Values("E10", "E37-1", "E37-2", "E10-position"));

TEST(PlantModel, DelayRotatesThePhaseOnly) {
  PlantModel m = e10_plant();
  const auto plain = m.response(2.0);
  m.delay_s = 0.05;
  const auto delayed = m.response(2.0);
  EXPECT_NEAR(std::abs(delayed), std::abs(plain), 1e-15);
  EXPECT_NEAR(std::remainder(std::arg(delayed) - std::arg(plain) + 0.1, 2.0 * std::numbers::pi), 0.0, 1e-14);
}

TEST(PlantModel, ParameterCount) {
  PlantModel m = e37_plant(1);
  EXPECT_EQ(m.parameter_count(), 11u);  // K, a, 2×4 modal, τ2
  m.rigid = RigidKind::kIntegrator;
  m.delay_s = 1e-3;
  EXPECT_EQ(m.parameter_count(), 11u);  // no a, plus T
  EXPECT_EQ(parameter_count(1, RigidKind::kRealPole, false, false), 6u);  // the C5.7 two-mass class
}

}  // namespace
}  // namespace servotwin::fit::test
