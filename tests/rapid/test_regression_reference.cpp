// The streamed statistics against tests/data/rapid/regression_reference.json, written by
// tools/reference/regression_reference.py: an independent numpy construction of Phi and y from
// the documented conventions, Gram entries summed with math.fsum (exactly rounded), theta by
// numpy.linalg.lstsq on the column-equilibrated Phi.
//
// Tolerances: Gram entries 1e-12 relative to sqrt(P_ii P_jj) (the blocked QR's backward error is
// ~sqrt(N) eps; the reference divides by 2 ts where the library multiplies by 1/(2 ts), ~1 ulp per
// stencil); first/last rows 1e-13 relative to the column scale; counts and the automatic deadband
// exactly / to 1e-12; theta 1e-7 relative (condition number of the equilibrated problem ~1e5).

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "servotwin/rapid/regression.hpp"
#include "test_regression_support.hpp"

namespace servotwin::rapid {
namespace {

const nlohmann::json& reference() {
  static const nlohmann::json data = [] {
    std::ifstream in(std::string(SERVOTWIN_TEST_DATA_DIR) + "/rapid/regression_reference.json");
    return nlohmann::json::parse(in);
  }();
  return data;
}

RegressorOptions options_of(const nlohmann::json& j) {
  RegressorOptions o;
  o.command_shift = j.at("command_shift").get<int>();
  o.trim_start = j.at("trim_start").get<std::size_t>();
  o.trim_end = j.at("trim_end").get<std::size_t>();
  if (!j.at("velocity_deadband").is_null()) o.velocity_deadband = j.at("velocity_deadband").get<double>();
  o.deadband_window = j.at("deadband_window").get<std::size_t>();
  return o;
}

class RegressionReference : public ::testing::TestWithParam<std::string> {};

TEST_P(RegressionReference, MatchesNumpy) {
  const nlohmann::json& ref = reference();
  const nlohmann::json& c = ref.at("cases").at(GetParam());
  const auto command = ref.at("command").get<std::vector<double>>();
  const auto actual = ref.at("actual").get<std::vector<double>>();
  const double ts = ref.at("ts").get<double>();
  const RegressorOptions options = options_of(c.at("options"));

  RegressionDiagnostics diag;
  const RegressionProblem problem = build_problem(command, actual, ts, options, &diag);
  EXPECT_EQ(diag.rows, c.at("rows").get<std::uint64_t>());
  EXPECT_EQ(problem.samples(), diag.rows);
  EXPECT_EQ(diag.positive_rows, c.at("positive_rows").get<std::uint64_t>());
  EXPECT_EQ(diag.negative_rows, c.at("negative_rows").get<std::uint64_t>());
  const double deadband = c.at("velocity_deadband").get<double>();
  EXPECT_NEAR(diag.velocity_deadband, deadband, 1e-12 * deadband);
  if (!options.velocity_deadband) {
    const double q = c.at("position_resolution").get<double>();
    const double noise = c.at("velocity_noise").get<double>();
    EXPECT_NEAR(diag.position_resolution, q, 1e-15 * q);
    EXPECT_NEAR(diag.velocity_noise, noise, 1e-12 * noise);
  }

  // Individual rows (first and last) from the dense construction.
  const Eigen::MatrixXd rows = regressor_matrix(command, actual, ts, options);
  ASSERT_EQ(rows.rows(), c.at("rows").get<Eigen::Index>());
  const Eigen::VectorXd scale = rows.cwiseAbs().colwise().maxCoeff();
  for (const char* which : {"first_row", "last_row"}) {
    const Eigen::Index r = std::string(which) == "first_row" ? 0 : rows.rows() - 1;
    const auto phi = c.at(which).at("phi").get<std::vector<double>>();
    for (int j = 0; j < kParameterCount; ++j) {
      EXPECT_NEAR(rows(r, j), phi[static_cast<std::size_t>(j)], 1e-13 * scale(j)) << which << " column " << j;
    }
    EXPECT_EQ(rows(r, kParameterCount), c.at(which).at("y").get<double>()) << which;
  }

  // Sufficient statistics.
  Eigen::MatrixXd expected(kParameterCount + 1, kParameterCount + 1);
  for (int i = 0; i < kParameterCount; ++i) {
    for (int j = 0; j < kParameterCount; ++j) expected(i, j) = c.at("P")[i][j].get<double>();
    expected(i, kParameterCount) = expected(kParameterCount, i) = c.at("R")[i].get<double>();
  }
  expected(kParameterCount, kParameterCount) = c.at("Gamma").get<double>();
  const NormalEquations ne = problem.normal_equations();
  EXPECT_LT(test::gram_difference(ne, expected), 1e-12);
  EXPECT_EQ(ne.n, diag.rows);
  EXPECT_EQ(ne.ts, ts);

  // Unconstrained least squares (the test's own triangular solve from the factor).
  const Vector8 theta = test::least_squares(problem);
  const auto expected_theta = c.at("theta").get<std::vector<double>>();
  for (int j = 0; j < kParameterCount; ++j) {
    const double e = expected_theta[static_cast<std::size_t>(j)];
    EXPECT_NEAR(theta(j), e, 1e-7 * std::abs(e)) << kRegressorNames[static_cast<std::size_t>(j)];
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, RegressionReference,
                         ::testing::Values("automatic", "shifted_trimmed", "negative_shift_small_window"));

}  // namespace
}  // namespace servotwin::rapid
