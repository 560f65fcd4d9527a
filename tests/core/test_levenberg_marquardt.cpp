// Levenberg–Marquardt (core/levenberg_marquardt.hpp). Expected values: closed forms (Rosenbrock
// minimum, a linear problem's normal-equation solution and covariance) and
// tests/data/fit/fit_reference.json written by tools/reference/fit_reference.py
// (scipy.optimize.least_squares).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "json_fixture.hpp"
#include "servotwin/core/levenberg_marquardt.hpp"

namespace servotwin::core {
namespace {

const nlohmann::json& fixture() {
  static const nlohmann::json data = test_support::read_json_fixture("fit/fit_reference.json", "fit_reference.py");
  return data;
}

bool rosenbrock(const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* j) {
  r << 10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0];
  if (j) *j << -20.0 * p[0], 10.0, -1.0, 0.0;
  return true;
}

TEST(LevenbergMarquardt, RosenbrockReachesTheClosedFormMinimum) {
  const LmResult r = levenberg_marquardt(rosenbrock, Eigen::Vector2d(-1.2, 1.0), 2);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_NEAR(r.parameters[0], 1.0, 1e-10);  // closed form: the only zero of both residuals
  EXPECT_NEAR(r.parameters[1], 1.0, 1e-10);
  EXPECT_LT(r.cost, 1e-20);
  EXPECT_GT(r.iterations, 5);                 // the valley makes it non-trivial
  EXPECT_EQ(static_cast<int>(r.history.size()), r.iterations);
  // Accepted steps never increase the cost.
  double last = r.initial_cost;
  for (const auto& it : r.history)
    if (it.accepted) {
      EXPECT_LE(it.cost, last);
      last = it.cost;
    }
}

TEST(LevenbergMarquardt, StepsDoNotDependOnTheUnitOfTheResiduals) {
  // Residuals in another unit (x 1000, e.g. um instead of mm) are the same problem: every trial
  // point, and so the iteration count and the history of gain ratios, must be the same.
  const auto scaled = [](double unit) {
    return [unit](const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* j) {
      rosenbrock(p, r, j);
      r *= unit;
      if (j) *j *= unit;
      return true;
    };
  };
  const LmResult a = levenberg_marquardt(scaled(1.0), Eigen::Vector2d(-1.2, 1.0), 2);
  const LmResult b = levenberg_marquardt(scaled(1000.0), Eigen::Vector2d(-1.2, 1.0), 2);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (std::size_t i = 0; i < a.history.size(); ++i) {
    EXPECT_EQ(a.history[i].accepted, b.history[i].accepted) << i;
    EXPECT_NEAR(a.history[i].lambda, b.history[i].lambda, 1e-9 * a.history[i].lambda) << i;
  }
  EXPECT_NEAR(a.parameters[0], b.parameters[0], 1e-10);
  EXPECT_NEAR(a.parameters[1], b.parameters[1], 1e-10);
}

TEST(LevenbergMarquardt, NumericJacobianGivesTheSameMinimum) {
  LmOptions o;
  o.numeric_jacobian = true;
  const LmResult r = levenberg_marquardt(rosenbrock, Eigen::Vector2d(-1.2, 1.0), 2, o);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_NEAR(r.parameters[0], 1.0, 1e-8);
  EXPECT_NEAR(r.parameters[1], 1.0, 1e-8);
}

TEST(LevenbergMarquardt, BoundedRosenbrockMatchesScipyAndClosedForm) {
  const auto& f = fixture()["lm_rosenbrock_bounded"];
  LmOptions o;
  o.upper = Eigen::Vector2d(0.5, std::numeric_limits<double>::infinity());
  const LmResult r = levenberg_marquardt(rosenbrock, Eigen::Vector2d(-1.2, 1.0), 2, o);
  ASSERT_TRUE(r.converged()) << r.message;
  // Closed form: x = 0.5 on the bound, y = x², cost ½(1 − x)² = 0.125 (scipy agrees).
  EXPECT_NEAR(r.parameters[0], f["solution"][0].get<double>(), 1e-9);
  EXPECT_NEAR(r.parameters[1], f["solution"][1].get<double>(), 1e-9);
  EXPECT_NEAR(r.cost, f["cost"].get<double>(), 1e-12);
}

TEST(LevenbergMarquardt, ExponentialFitMatchesScipyLeastSquares) {
  const auto& f = fixture()["lm_exponential"];
  const auto t = f["t"].get<std::vector<double>>();
  const auto y = f["y"].get<std::vector<double>>();
  auto residual = [&](const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* j) {
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double e = std::exp(-p[1] * t[i]);
      const auto k = static_cast<Eigen::Index>(i);
      r[k] = p[0] * e + p[2] - y[i];
      if (j) j->row(k) << e, -p[0] * t[i] * e, 1.0;
    }
    return true;
  };
  const auto x0 = f["initial"].get<std::vector<double>>();
  const LmResult r = levenberg_marquardt(residual, Eigen::Vector3d(x0[0], x0[1], x0[2]), t.size());
  ASSERT_TRUE(r.converged()) << r.message;
  const auto sol = f["solution"].get<std::vector<double>>();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.parameters[i], sol[static_cast<std::size_t>(i)], 1e-8) << i;
  EXPECT_NEAR(r.cost, f["cost"].get<double>(), 1e-12);
  EXPECT_NEAR(r.sigma2, f["sigma2"].get<double>(), 1e-12);
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      const double expected = f["covariance"][static_cast<std::size_t>(i)][static_cast<std::size_t>(k)].get<double>();
      EXPECT_NEAR(r.covariance(i, k), expected, 1e-6 * std::abs(expected) + 1e-14) << i << "," << k;
    }
}

TEST(LevenbergMarquardt, LinearProblemSolvesInOneStepWithTheNormalEquationCovariance) {
  // r = A p − b: the minimum and covariance have the closed forms (AᵀA)⁻¹Aᵀb and σ²(AᵀA)⁻¹.
  Eigen::MatrixXd a(5, 2);
  a << 1, 0, 1, 1, 1, 2, 1, 3, 1, 4;
  Eigen::VectorXd b(5);
  b << 0.1, 1.1, 1.9, 3.2, 3.9;
  auto residual = [&](const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* j) {
    r = a * p - b;
    if (j) *j = a;
    return true;
  };
  LmOptions o;
  o.initial_lambda = 1e-12;
  const LmResult r = levenberg_marquardt(residual, Eigen::Vector2d(0, 0), 5, o);
  ASSERT_TRUE(r.converged()) << r.message;
  const Eigen::Matrix2d ata = a.transpose() * a;
  const Eigen::Vector2d expected = ata.ldlt().solve(a.transpose() * b);
  EXPECT_NEAR(r.parameters[0], expected[0], 1e-10);
  EXPECT_NEAR(r.parameters[1], expected[1], 1e-10);
  const double sigma2 = (a * expected - b).squaredNorm() / 3.0;
  const Eigen::Matrix2d cov = sigma2 * ata.inverse();
  EXPECT_NEAR((r.covariance - cov).norm(), 0.0, 1e-10 * cov.norm());
  LmOptions known = o;
  known.covariance_scale = LmCovarianceScale::kKnown;
  const LmResult rk = levenberg_marquardt(residual, Eigen::Vector2d(0, 0), 5, known);
  EXPECT_NEAR((rk.covariance - ata.inverse()).norm(), 0.0, 1e-10 * ata.inverse().norm());
}

TEST(LevenbergMarquardt, RankDeficientJacobianGivesNanCovariance) {
  // r depends on p0 + p1 only: the parameters are not separately identifiable.
  auto residual = [](const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* j) {
    r << p[0] + p[1] - 1.0, 2.0 * (p[0] + p[1]) - 2.5, p[0] + p[1];
    if (j) *j << 1, 1, 2, 2, 1, 1;
    return true;
  };
  const LmResult r = levenberg_marquardt(residual, Eigen::Vector2d(0, 0), 3);
  EXPECT_EQ(r.jacobian_rank, 1);
  EXPECT_TRUE(std::isnan(r.covariance(0, 0)));
}

TEST(LevenbergMarquardt, IterationLimitIsReportedAsNotConverged) {
  LmOptions o;
  o.max_iterations = 3;
  const LmResult r = levenberg_marquardt(rosenbrock, Eigen::Vector2d(-1.2, 1.0), 2, o);
  EXPECT_FALSE(r.converged());
  EXPECT_EQ(r.status, LmStatus::kMaxIterations);
  EXPECT_EQ(r.iterations, 3);
  EXPECT_FALSE(r.message.empty());
}

TEST(LevenbergMarquardt, InvalidStartAndRejectedRegion) {
  auto reject_all = [](const Eigen::VectorXd&, Eigen::VectorXd&, Eigen::MatrixXd*) { return false; };
  const LmResult bad = levenberg_marquardt(reject_all, Eigen::Vector2d(0, 0), 2);
  EXPECT_EQ(bad.status, LmStatus::kInvalidStart);
  // ln-domain residual valid only for p > 0: steps into p ≤ 0 are rejected and damped instead.
  auto log_fit = [](const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* j) {
    if (p[0] <= 0.0) return false;
    r << std::log(p[0]) - std::log(1e-3);
    if (j) (*j)(0, 0) = 1.0 / p[0];
    return true;
  };
  const LmResult r = levenberg_marquardt(log_fit, Eigen::VectorXd::Constant(1, 5.0), 1);
  ASSERT_TRUE(r.converged()) << r.message;
  EXPECT_NEAR(r.parameters[0], 1e-3, 1e-12);
}

TEST(LevenbergMarquardt, InconsistentArgumentsThrow) {
  LmOptions o;
  o.lower = Eigen::Vector3d::Zero();
  EXPECT_THROW(levenberg_marquardt(rosenbrock, Eigen::Vector2d(0, 0), 2, o), std::invalid_argument);
  EXPECT_THROW(levenberg_marquardt(rosenbrock, Eigen::Vector2d(0, 0), 0), std::invalid_argument);
}

}  // namespace
}  // namespace servotwin::core
