#include "servotwin/core/riccati.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace servotwin::core {
namespace {

// Fixture: tests/data/frf/frf_observer_reference.json, section "care", written by
// tools/reference/frf_observer_reference.py with scipy.linalg.solve_continuous_are.
const nlohmann::json& care_cases() {
  static const nlohmann::json data = [] {
    const std::string path = std::string(SERVOTWIN_TEST_DATA_DIR) + "/frf/frf_observer_reference.json";
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    return nlohmann::json::parse(in).at("care");
  }();
  return data;
}

Eigen::MatrixXd matrix(const nlohmann::json& rows) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows.front().size()));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) m(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)].get<double>();
  return m;
}

double max_real_eigenvalue(const Eigen::MatrixXd& m) {
  return Eigen::ComplexEigenSolver<Eigen::MatrixXd>(m, false).eigenvalues().real().maxCoeff();
}

TEST(Riccati, MatchesScipyOnObserverAndRandomProblems) {
  for (const auto& c : care_cases()) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Eigen::MatrixXd a = matrix(c.at("A")), b = matrix(c.at("B")), q = matrix(c.at("Q")), r = matrix(c.at("R"));
    CareReport report;
    const Eigen::MatrixXd x = solve_care(a, b, q, r, &report);
    const Eigen::MatrixXd expected = matrix(c.at("X"));
    EXPECT_LT((x - expected).norm(), 1e-9 * expected.norm());
    EXPECT_LT(report.relative_residual, 1e-13);
    EXPECT_LT((x - x.transpose()).norm(), 1e-14 * x.norm());
    // Stabilizing: A - B R^-1 B^T X is Hurwitz (definition of the solution scipy returns).
    EXPECT_LT(max_real_eigenvalue(a - b * r.llt().solve(b.transpose()) * x), 0.0);
  }
}

TEST(Riccati, DoubleIntegratorClosedForm) {
  // x'' = u, Q = I, R = 1: p12^2 = 1, p22^2 = 2 p12 + 1, p11 = p12 p22 (hand solution of the three
  // scalar equations) => X = [[sqrt 3, 1], [1, sqrt 3]].
  Eigen::MatrixXd a(2, 2), b(2, 1);
  a << 0, 1, 0, 0;
  b << 0, 1;
  const Eigen::MatrixXd x = solve_care(a, b, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Identity(1, 1));
  EXPECT_NEAR(x(0, 0), std::sqrt(3.0), 1e-13);
  EXPECT_NEAR(x(0, 1), 1.0, 1e-13);
  EXPECT_NEAR(x(1, 0), 1.0, 1e-13);
  EXPECT_NEAR(x(1, 1), std::sqrt(3.0), 1e-13);
}

TEST(Riccati, ScalarClosedFormIsUnitInvariant) {
  // Scalar CARE 2 a x - b^2 x^2 / r + q = 0: x = r (a + s) / b^2 with s = sqrt(a^2 + b^2 q / r),
  // evaluated without cancellation: that form for a >= 0, the equal q / (s - a) for a < 0.
  for (const double a : {-3.0, 0.0, 2.5}) {
    for (const double scale : {1e-3, 1.0, 1e3}) {  // b scaled by 1/scale: x scales by scale^2
      const double b = 0.7 / scale, q = 4.0, r = 0.3;
      const double s = std::sqrt(a * a + b * b * q / r);
      const double expected = a >= 0.0 ? r * (a + s) / (b * b) : q / (s - a);
      const Eigen::MatrixXd x = solve_care(Eigen::MatrixXd::Constant(1, 1, a), Eigen::MatrixXd::Constant(1, 1, b),
                                           Eigen::MatrixXd::Constant(1, 1, q), Eigen::MatrixXd::Constant(1, 1, r));
      EXPECT_NEAR(x(0, 0), expected, 1e-12 * expected) << "a=" << a << " scale=" << scale;
    }
  }
}

TEST(Riccati, FilterFormIsTheDualProblem) {
  // A Y + Y A^T - Y C^T V^-1 C Y + W = 0 checked by its own residual, and the observer A - L C stable.
  const auto& c = care_cases().at(2);  // random_unstable_4x1: use A^T as a system matrix
  const Eigen::MatrixXd a = matrix(c.at("A")).transpose(), cm = matrix(c.at("B")).transpose();
  const Eigen::MatrixXd w = matrix(c.at("Q")), v = matrix(c.at("R"));
  const Eigen::MatrixXd y = solve_care_filter(a, cm, w, v);
  const Eigen::MatrixXd residual = a * y + y * a.transpose() - y * cm.transpose() * v.inverse() * cm * y + w;
  EXPECT_LT(residual.norm(), 1e-11 * (w.norm() + y.norm()));
  EXPECT_LT(max_real_eigenvalue(a - y * cm.transpose() * v.inverse() * cm), 0.0);
}

TEST(Lyapunov, ScalarAndResidual) {
  // a x + x a + q = 0 => x = -q / (2 a).
  EXPECT_NEAR(solve_lyapunov(Eigen::MatrixXd::Constant(1, 1, -2.0), Eigen::MatrixXd::Constant(1, 1, 3.0))(0, 0), 0.75, 1e-15);
  Eigen::MatrixXd a(3, 3), q(3, 3);
  a << -1, 2, 0, -2, -1, 1, 0, 0.5, -3;
  q << 2, 1, 0, 1, 3, 0.5, 0, 0.5, 1;
  const Eigen::MatrixXd x = solve_lyapunov(a, q);
  EXPECT_LT((a.transpose() * x + x * a + q).norm(), 1e-13 * q.norm());
}

TEST(Riccati, RejectsBadShapesAndProblemsWithoutSolution) {
  const Eigen::MatrixXd i2 = Eigen::MatrixXd::Identity(2, 2);
  EXPECT_THROW(solve_care(i2, Eigen::MatrixXd::Ones(3, 1), i2, Eigen::MatrixXd::Ones(1, 1)), std::invalid_argument);
  EXPECT_THROW(solve_care(i2, Eigen::MatrixXd::Ones(2, 1), i2, Eigen::MatrixXd::Constant(1, 1, -1.0)), std::invalid_argument);
  Eigen::MatrixXd q_nonsym = i2;
  q_nonsym(0, 1) = 1.0;
  EXPECT_THROW(solve_care(i2, Eigen::MatrixXd::Ones(2, 1), q_nonsym, Eigen::MatrixXd::Ones(1, 1)), std::invalid_argument);
  // Undamped oscillator without input: Hamiltonian eigenvalues +-j on the imaginary axis.
  Eigen::MatrixXd osc(2, 2);
  osc << 0, 1, -1, 0;
  EXPECT_THROW(solve_care(osc, Eigen::MatrixXd::Zero(2, 1), i2, Eigen::MatrixXd::Ones(1, 1)), std::domain_error);
  // Unstable and uncontrollable: no stabilizing solution.
  EXPECT_THROW(solve_care(Eigen::MatrixXd::Constant(1, 1, 1.0), Eigen::MatrixXd::Zero(1, 1), Eigen::MatrixXd::Ones(1, 1),
                          Eigen::MatrixXd::Ones(1, 1)),
               std::domain_error);
}

}  // namespace
}  // namespace servotwin::core
