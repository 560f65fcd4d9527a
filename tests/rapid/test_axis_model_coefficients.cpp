// Eq. 3.10 normalisation (theta <-> Eq. 3.3 coefficients), checked against the closed forms of
// thesis Eq. 3.14 (alpha in terms of the pole parameters p, omega_n, zeta).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/rapid/axis_model.hpp"
#include "test_axis_model_support.hpp"

namespace servotwin::rapid {
namespace {

// Thesis Table 3.4, PID X axis, "actual" column.
ModelCoefficients pid_x() {
  return {.a1 = 192.65, .a2 = 44356.23, .a3 = 316830.21, .b0 = 0.0, .b1 = 190.10, .b2 = 44356.23, .d0 = 441.0, .d1 = -302.0};
}

TEST(AxisModelCoefficients, ThetaFollowsEquation310) {
  const ModelCoefficients c = pid_x();
  const Vector8 theta = theta_from_coefficients(c);
  // Column order of regression.hpp: alpha_i, alpha_1, alpha_2, beta_0, beta_1, beta_2, delta+, delta-.
  EXPECT_DOUBLE_EQ(theta(0), 316830.21 / 44356.23);
  EXPECT_DOUBLE_EQ(theta(1), 192.65 / 44356.23);
  EXPECT_DOUBLE_EQ(theta(2), 1.0 / 44356.23);
  EXPECT_DOUBLE_EQ(theta(3), 1.0);  // beta_0 = b2/a2
  EXPECT_DOUBLE_EQ(theta(4), 190.10 / 44356.23);
  EXPECT_DOUBLE_EQ(theta(5), 0.0);
  EXPECT_DOUBLE_EQ(theta(6), 441.0 / 44356.23);
  EXPECT_DOUBLE_EQ(theta(7), -302.0 / 44356.23);
}

TEST(AxisModelCoefficients, RoundTripIsExactToRounding) {
  const ModelCoefficients cases[] = {
      pid_x(),
      {.a1 = 372.76, .a2 = 62009.83, .a3 = 1527104.87, .b0 = 0.0, .b1 = 0.0, .b2 = 11106.33, .d0 = 441.0, .d1 = -302.0},
      {.a1 = 566.95, .a2 = 370137.94, .a3 = 15346572.85, .b0 = 0.85, .b1 = 574.83, .b2 = 370142.25, .d0 = 2367.0, .d1 = -1858.0},
      {.a1 = -3.0, .a2 = -2.0e-3, .a3 = 0.0, .b0 = -1.5, .b1 = 7.0e5, .b2 = 1.0e-9, .d0 = -4.0, .d1 = 9.0},
  };
  for (const ModelCoefficients& c : cases) {
    const ModelCoefficients back = coefficients_from_theta(theta_from_coefficients(c));
    test::expect_coefficients_near(back, c, 4.0 * std::numeric_limits<double>::epsilon());
  }
}

TEST(AxisModelCoefficients, AlphasMatchEquation314PoleParameters) {
  // s^3 + a1 s^2 + a2 s + a3 = (s + p)(s^2 + 2 zeta wn s + wn^2) (Eq. 3.7).
  const double p = 2.0 * std::numbers::pi * 4.68, wn = 2.0 * std::numbers::pi * 36.26, zeta = 0.75;
  const ModelCoefficients c{.a1 = p + 2.0 * zeta * wn, .a2 = wn * wn + 2.0 * p * zeta * wn, .a3 = p * wn * wn, .b2 = 1.0};
  const Vector8 theta = theta_from_coefficients(c);
  const double den = wn * wn + 2.0 * p * zeta * wn;
  EXPECT_NEAR(theta(0), p * wn * wn / den, 1e-14 * p);
  EXPECT_NEAR(theta(1), (p + 2.0 * zeta * wn) / den, 1e-14 * theta(1));
  EXPECT_NEAR(theta(2), 1.0 / den, 1e-14 * theta(2));
}

TEST(AxisModelCoefficients, RejectsZeroOrNonFiniteScale) {
  Vector8 theta = Vector8::Ones();
  theta(2) = 0.0;
  EXPECT_THROW((void)coefficients_from_theta(theta), core::InputError);
  theta(2) = 1.0;
  theta(5) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)coefficients_from_theta(theta), core::InputError);
  ModelCoefficients c = pid_x();
  c.a2 = 0.0;
  EXPECT_THROW((void)theta_from_coefficients(c), core::InputError);
  c.a2 = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)theta_from_coefficients(c), core::InputError);
}

}  // namespace
}  // namespace servotwin::rapid
