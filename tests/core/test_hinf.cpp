// H-infinity synthesis (core/hinf.hpp). Expected values: GNU Octave's control package in
// tests/data/core/hinf_reference.json, written by tools/reference/hinf_reference.m: the central
// controller at a fixed gamma from hinfsyn SUBOPTIMAL (SLICOT SB10FD) and the optimal gamma from a
// bisection over the same call. The plants are the mixed-sensitivity problem of catalog C7.14 on two
// normalized two-mass drives and a MIMO problem with every block of D11, D22 != 0 and an unstable A.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>
#include <vector>

#include "json_fixture.hpp"
#include "servotwin/core/hinf.hpp"
#include "servotwin/core/norms.hpp"

namespace servotwin::core {
namespace {
namespace hinf_test {

const nlohmann::json& fixture() {
  static const nlohmann::json data = test_support::read_json_fixture("core/hinf_reference.json", "hinf_reference.m");
  return data;
}

struct Case {
  std::string name;
  StateSpace plant;
  Eigen::Index ny = 1, nu = 1;
  double gamma_optimal = 0.0, gamma_suboptimal = 0.0, closed_loop_norm = 0.0;
  nlohmann::json raw;
};

Case read_case(const nlohmann::json& c) {
  const auto n = c["states"].get<Eigen::Index>();
  const auto m = c["inputs"].get<Eigen::Index>();
  const auto p = c["outputs"].get<Eigen::Index>();
  Case out;
  out.name = c["name"].get<std::string>();
  out.plant = {test_support::octave_matrix(c["A"], n, n), test_support::octave_matrix(c["B"], n, m),
               test_support::octave_matrix(c["C"], p, n), test_support::octave_matrix(c["D"], p, m)};
  out.ny = c["nmeas"].get<Eigen::Index>();
  out.nu = c["ncon"].get<Eigen::Index>();
  out.gamma_optimal = c["gamma_optimal"].get<double>();
  out.gamma_suboptimal = c["gamma_suboptimal"].get<double>();
  out.closed_loop_norm = c["closed_loop_norm"].get<double>();
  out.raw = c;
  return out;
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const auto& c : fixture()["cases"]) out.push_back(read_case(c));
  return out;
}

TEST(Hinf, OptimalGammaMatchesOctave) {
  HinfOptions options;
  options.relative_tolerance = 1e-7;
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const HinfSynthesis s = hinf_synthesis(c.plant, c.ny, c.nu, options);
    // Both bisections take a gamma as feasible when the central controller's closed loop is
    // stable with its norm below gamma. Near the optimum the controller is ill-conditioned: SLICOT
    // SB10FD gives up a little earlier than we do on velocity_r2, velocity_r4_friction and
    // position_r3 (by 7e-6, 7e-5 and 3e-4 of gamma), we give up 1e-4 earlier on velocity_r3_slow
    // (w0S = 0.05: weights over four decades). Our gamma is an upper bound of the optimum either
    // way: its controller's closed loop is evaluated (hinf_norm) and meets it (checked below).
    EXPECT_LE(s.gamma_optimal, c.gamma_optimal * (1.0 + 2e-4));
    EXPECT_GE(s.gamma_optimal, c.gamma_optimal * (1.0 - 1e-3));
    EXPECT_LT(s.gamma_infeasible, s.gamma_optimal);
    EXPECT_LE(s.gamma_optimal / s.gamma_infeasible, 1.0 + 1e-7 + 1e-12);
    EXPECT_LE(s.closed_loop_norm, s.design.gamma * (1.0 + 1e-6));
    EXPECT_GT(s.closed_loop_norm, s.gamma_infeasible * (1.0 - 1e-6));
  }
}

TEST(Hinf, CentralControllerMatchesOctaveAtAFixedGamma) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const auto k = hinf_central_controller(c.plant, c.ny, c.nu, c.gamma_suboptimal);
    ASSERT_TRUE(k.has_value());
    EXPECT_EQ(k->controller.states(), c.raw["controller_order"].get<Eigen::Index>());
    const auto& omega = c.raw["omega"];
    double scale = 0.0;
    for (std::size_t i = 0; i < omega.size(); ++i)
      scale = std::max(scale, std::hypot(c.raw["K_re"][i].get<double>(), c.raw["K_im"][i].get<double>()));
    for (std::size_t i = 0; i < omega.size(); ++i) {
      const std::complex<double> expected(c.raw["K_re"][i].get<double>(), c.raw["K_im"][i].get<double>());
      const std::complex<double> got = frequency_response(k->controller, omega[i].get<double>(), 0, 0);
      EXPECT_LT(std::abs(got - expected), 1e-6 * scale) << "omega " << omega[i] << ": " << got << " vs " << expected;
    }
    const StateSpace loop = lft_lower(c.plant, k->controller, c.ny, c.nu);
    EXPECT_NEAR(hinf_norm(loop, 1e-9).value, c.closed_loop_norm, 1e-6 * c.closed_loop_norm);
  }
}

TEST(Hinf, NoControllerBelowTheOptimum) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    EXPECT_FALSE(hinf_central_controller(c.plant, c.ny, c.nu, c.gamma_optimal * (1.0 - 1e-3)).has_value());
    EXPECT_TRUE(hinf_central_controller(c.plant, c.ny, c.nu, c.gamma_optimal * (1.0 + 1e-4)).has_value());
  }
}

TEST(Hinf, BackoffGivesTheControllerAtTheBackedOffGamma) {
  const Case c = cases().front();
  HinfOptions options;
  options.backoff = 1.2;
  const HinfSynthesis s = hinf_synthesis(c.plant, c.ny, c.nu, options);
  EXPECT_NEAR(s.design.gamma, 1.2 * s.gamma_optimal, 1e-12 * s.gamma_optimal);
  EXPECT_LT(s.closed_loop_norm, s.design.gamma);
  EXPECT_GT(s.closed_loop_norm, s.gamma_infeasible);  // no controller does better than the optimum
}

// Units of u and y (a torque in N m or mN m) change the controller by the same factors and
// nothing else: gamma is a property of the weighted problem.
TEST(Hinf, ScalingControlsAndMeasurementsScalesTheController) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    StateSpace scaled = c.plant;
    const double su = 1e3, sy = 1e-2;  // u' = su u, y' = sy y
    scaled.B.rightCols(c.nu) /= su;
    scaled.D.topRightCorner(scaled.outputs(), c.nu) /= su;
    scaled.C.bottomRows(c.ny) *= sy;
    scaled.D.bottomRows(c.ny) *= sy;
    const auto k = hinf_central_controller(c.plant, c.ny, c.nu, c.gamma_suboptimal);
    const auto ks = hinf_central_controller(scaled, c.ny, c.nu, c.gamma_suboptimal);
    ASSERT_TRUE(k && ks);
    for (const double w : {0.01, 0.3, 1.0, 3.0, 30.0}) {
      const std::complex<double> expected = frequency_response(k->controller, w, 0, 0) * su / sy;
      EXPECT_LT(std::abs(frequency_response(ks->controller, w, 0, 0) - expected), 1e-8 * std::abs(expected));
    }
  }
}

TEST(Hinf, RejectsSingularProblemsAndBadArguments) {
  Case c = cases().front();
  StateSpace no_control_weight = c.plant;
  no_control_weight.D.topRightCorner(no_control_weight.outputs() - c.ny, c.nu).setZero();
  try {
    (void)hinf_synthesis(no_control_weight, c.ny, c.nu);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("D12"), std::string::npos) << e.what();
  }
  StateSpace no_noise = c.plant;
  no_noise.D.bottomLeftCorner(c.ny, no_noise.inputs() - c.nu).setZero();
  EXPECT_THROW((void)hinf_synthesis(no_noise, c.ny, c.nu), std::invalid_argument);
  EXPECT_THROW((void)hinf_central_controller(c.plant, c.ny, c.nu, 0.0), std::invalid_argument);
  EXPECT_THROW((void)hinf_central_controller(c.plant, 0, c.nu, 2.0), std::invalid_argument);
  EXPECT_THROW((void)hinf_central_controller(c.plant, c.ny, c.plant.inputs(), 2.0), std::invalid_argument);
  HinfOptions bad;
  bad.backoff = 0.9;
  EXPECT_THROW((void)hinf_synthesis(c.plant, c.ny, c.nu, bad), std::invalid_argument);
}

// An unstable mode that u cannot reach: no gamma is feasible, and synthesis says so instead of
// returning a controller.
TEST(Hinf, UnstabilizablePlantIsReported) {
  StateSpace p;
  p.A = Eigen::MatrixXd::Zero(2, 2);
  p.A << 1.0, 0.0, 0.0, -1.0;
  p.B = Eigen::MatrixXd::Zero(2, 2);
  p.B << 1.0, 0.0, 0.0, 1.0;  // w drives the unstable state, u only the stable one
  p.C = Eigen::MatrixXd::Zero(3, 2);
  p.C << 1.0, 0.0, 0.0, 0.0, 1.0, 1.0;
  p.D = Eigen::MatrixXd::Zero(3, 2);
  p.D(1, 1) = 1.0;
  p.D(2, 0) = 1.0;
  HinfOptions options;
  options.gamma_max = 1e6;
  EXPECT_THROW((void)hinf_synthesis(p, 1, 1, options), std::domain_error);
}

}  // namespace hinf_test
}  // namespace
}  // namespace servotwin::core
