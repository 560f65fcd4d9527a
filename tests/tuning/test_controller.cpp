// The controller's state-space form and its discretization. References: the PI/PID formula
// u = (wp kp + ki/s + wd kd s/(τs+1)) ω* − (kp + ki/s + kd s/(τs+1)) ωm evaluated directly, and the
// Tustin map's defining property (exact at the prewarp frequency).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/tuning/controller.hpp"

namespace servotwin::tuning {
namespace {

using Complex = std::complex<double>;

void expect_matches_formula(const PidGains& g) {
  const core::StateSpace sys = controller_state_space(g);
  for (double w : {1e-3, 0.1, 1.0, 7.0, 300.0}) {
    const Complex s(0.0, w);
    const Complex d = g.kd == 0.0 ? Complex(0.0) : g.kd * s / (g.tau * s + 1.0);
    const Complex ref = g.wp * g.kp + g.ki / s + g.wd * d;
    const Complex fb = g.kp + g.ki / s + d;
    EXPECT_LT(std::abs(core::frequency_response(sys, w, 0, 0) - ref), 1e-11 * std::abs(ref)) << w;
    EXPECT_LT(std::abs(core::frequency_response(sys, w, 0, 1) + fb), 1e-11 * std::abs(fb)) << w;
  }
}

TEST(ControllerStateSpace, PiAndPidMatchTheirFormulas) {
  expect_matches_formula({3.2, 1.1, 0.0, 0.0, 0.7, 0.0});
  expect_matches_formula({3.2, 1.1, 0.9, 0.03, 0.7, 0.0});
  expect_matches_formula({3.2, 1.1, 0.9, 0.03, 1.0, 0.4});
  EXPECT_EQ(controller_state_space({3.2, 1.1}).states(), 1);
  EXPECT_EQ(controller_state_space({3.2, 1.1, 0.9, 0.03}).states(), 2);
}

TEST(ControllerStateSpace, TustinIsExactAtThePrewarpFrequency) {
  const PidGains g{250.0, 9000.0, 0.4, 2e-4, 1.0, 0.0};
  const double ts = 1.0 / 8000.0, wp = 2.0 * std::numbers::pi * 300.0;
  const core::DiscreteStateSpace d = discretize_controller(g, ts, wp);
  const core::StateSpace c = controller_state_space(g);
  const Complex at_wp = core::frequency_response(d, wp)(0, 1);
  EXPECT_LT(std::abs(at_wp - core::frequency_response(c, wp, 0, 1)), 1e-9 * std::abs(at_wp));
  // Without prewarping the map is exact only as ω ts → 0: 1e-3 relative at 10 Hz for 8 kHz.
  const core::DiscreteStateSpace plain = discretize_controller(g, ts);
  const double w10 = 2.0 * std::numbers::pi * 10.0;
  const Complex a = core::frequency_response(plain, w10)(0, 1), b = core::frequency_response(c, w10, 0, 1);
  EXPECT_LT(std::abs(a - b), 1e-3 * std::abs(b));
  EXPECT_DOUBLE_EQ(plain.ts, ts);
}

TEST(ControllerStateSpace, BadPeriodsAreInputErrors) {
  EXPECT_THROW((void)discretize_controller({1.0, 1.0}, 0.0), core::InputError);
  EXPECT_THROW((void)discretize_controller({1.0, 1.0}, std::nan("")), core::InputError);
  EXPECT_THROW((void)discretize_controller({1.0, 1.0}, 1e-3, 2.0 * std::numbers::pi * 600.0), core::InputError);
  EXPECT_THROW((void)controller_state_space({1.0, 1.0, 0.5, 0.0}), std::invalid_argument);
}

TEST(ControllerStructure, NamesRoundTrip) {
  for (Structure s : {Structure::kPi, Structure::kPid, Structure::kPiP}) {
    EXPECT_EQ(structure_from_string(to_string(s)), s);
  }
  EXPECT_FALSE(structure_from_string("lqr").has_value());
}

}  // namespace
}  // namespace servotwin::tuning
