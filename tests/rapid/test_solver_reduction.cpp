// The solvers' shared reduction (theta2 eliminated) and Eq. 4.12's fast fitness, checked against
// the direct objective f = 1/2 ||y - Phi theta||^2 of the factor, an independent elimination of
// theta2 (ReferenceObjective), the thesis's Eq. 4.11-4.12 computed literally from normal equations,
// and Eigen's least squares on the raw regressor matrix.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "rapid/test_solver_support.hpp"
#include "servotwin/rapid/solver.hpp"
#include "servotwin/rapid/solver_detail.hpp"

namespace servotwin::rapid {
namespace {

using test::random_problem;

Eigen::Vector3d random_theta1(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> lp(std::log(2.0), std::log(3000.0)), z(0.1, 2.5);
  return theta1_from_poles(std::exp(lp(rng)), std::exp(lp(rng)), z(rng));
}

TEST(SolverReduction, ReducedObjectiveIsTheMinimumOverTheta2) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const RegressionProblem problem = random_problem(rng, 10.0, 200.0, 0.5, 0.05);
    const detail::ReducedProblem reduced(problem);
    const test::ReferenceObjective reference(problem);
    for (int k = 0; k < 10; ++k) {
      const Eigen::Vector3d t1 = random_theta1(rng);
      const Vector8 theta = reduced.theta(t1);
      const double f = reduced.objective(t1);
      EXPECT_NEAR(problem.objective(theta), f, 1e-12 * f);
      EXPECT_NEAR(reference(t1), f, 1e-10 * f);
      // theta2 is optimal: Phi2^T (Phi theta - y) = 0.
      const NormalEquations ne = problem.normal_equations();
      const Vector8 g = ne.P * theta - ne.R;
      const Vector8 scale = ne.P.cwiseAbs() * theta.cwiseAbs() + ne.R.cwiseAbs();
      for (int j = 3; j < kParameterCount; ++j) EXPECT_LE(std::abs(g(j)), 1e-9 * scale(j)) << j;
      // and any other theta2 is worse.
      Vector8 other = theta;
      other(3) *= 1.001;
      EXPECT_GT(problem.objective(other), f);
    }
  }
}

TEST(SolverReduction, Eq412QuadraticFormEqualsTheDirectObjective) {
  // Eq. 4.12 as derived: theta = T mu, T = [[0, I3], [R*, -P*]], mu = (1, alpha_i, alpha_1, alpha_2),
  // f = 1/2 (mu^T T^T P T mu - 2 R^T T mu + Gamma). Both the literal normal-equation form and the
  // library's factored form (quadratic_form(), which the GA evaluates) must give f.
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 30; ++trial) {
    const RegressionProblem problem = random_problem(rng, 20.0, 300.0, 0.7, 0.02);
    const NormalEquations ne = problem.normal_equations();
    const detail::ThesisQuadraticForm thesis = detail::thesis_quadratic_form(ne);
    const detail::ReducedProblem reduced(problem);
    const Eigen::Matrix4d m = reduced.quadratic_form();
    for (int k = 0; k < 10; ++k) {
      const Eigen::Vector3d t1 = random_theta1(rng);
      Eigen::Vector4d mu;
      mu << 1.0, t1;
      const double direct = problem.objective(reduced.theta(t1));
      // The expanded forms cancel: their rounding is relative to the magnitude of the terms.
      const double terms = mu.cwiseAbs().dot(thesis.a.cwiseAbs() * mu.cwiseAbs()) +
                           thesis.b.cwiseAbs().dot(mu.cwiseAbs()) + thesis.gamma;
      EXPECT_NEAR(detail::evaluate(thesis, t1), direct, 1e-11 * terms);
      EXPECT_NEAR(0.5 * mu.dot(m * mu), direct, 1e-11 * terms);
      EXPECT_NEAR(reduced.objective(t1), direct, 1e-12 * direct);
      // theta = T mu reproduces the library's theta2.
      const Vector8 theta_t = thesis.t * mu;
      const Vector8 theta_r = reduced.theta(t1);
      for (int j = 3; j < kParameterCount; ++j) {
        EXPECT_NEAR(theta_t(j), theta_r(j), 1e-6 * (std::abs(theta_r(j)) + 1e-12)) << j;
      }
    }
  }
}

TEST(SolverReduction, LeastSquaresMatchesEigenOnTheRawRegressors) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int trial = 0; trial < 30; ++trial) {
    Eigen::MatrixXd phi(80, kParameterCount);
    for (int i = 0; i < phi.rows(); ++i) {
      for (int j = 0; j < kParameterCount; ++j) phi(i, j) = gauss(rng) * std::pow(10.0, j % 4);
    }
    Eigen::VectorXd y(phi.rows());
    for (int i = 0; i < y.size(); ++i) y(i) = gauss(rng);
    const RegressionProblem problem = test::problem_from_rows(phi, y, 1e-3);
    const Vector8 expected = phi.colPivHouseholderQr().solve(y);
    const Vector8 got = detail::ReducedProblem(problem).least_squares();
    for (int j = 0; j < kParameterCount; ++j) EXPECT_NEAR(got(j), expected(j), 1e-9 * expected.cwiseAbs().maxCoeff());
    const Solution ls = solve(problem, Method::Ls, default_bounds(1e-3));
    EXPECT_NEAR(ls.objective, 0.5 * (y - phi * expected).squaredNorm(), 1e-12 * y.squaredNorm());
  }
}

TEST(SolverReduction, ZeroFrictionColumnIsReportedAndItsParameterFixedAtZero) {
  // The axis never moved in the negative direction: the -NV regressor is all zero.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::MatrixXd phi(60, kParameterCount);
  for (int i = 0; i < phi.rows(); ++i) {
    for (int j = 0; j < kParameterCount; ++j) phi(i, j) = gauss(rng);
  }
  phi.col(7).setZero();
  Eigen::VectorXd y = phi * Vector8::LinSpaced(0.1, 0.8);
  for (int i = 0; i < y.size(); ++i) y(i) += 0.01 * gauss(rng);
  const RegressionProblem problem = test::problem_from_rows(phi, y, 1e-3);
  for (const Method m : {Method::Ls, Method::Exact, Method::Ga}) {
    SolveOptions o;
    o.ga.population = 200;
    o.ga.generations = 20;
    const Solution s = solve(problem, m, default_bounds(1e-3), o);
    EXPECT_EQ(s.theta(7), 0.0) << method_name(m);
    EXPECT_THAT(s.warnings, testing::Contains(testing::HasSubstr("'-NV' is zero: delta- not identifiable")))
        << method_name(m);
  }
  // Least squares on the seven remaining columns.
  const Eigen::MatrixXd phi7 = phi.leftCols(7);
  const Eigen::VectorXd expected = phi7.colPivHouseholderQr().solve(y);
  const Vector8 got = solve(problem, Method::Ls, default_bounds(1e-3)).theta;
  for (int j = 0; j < 7; ++j) EXPECT_NEAR(got(j), expected(j), 1e-10 * expected.cwiseAbs().maxCoeff());
}

TEST(SolverReduction, DependentRegressorIsDetectedFromRowsAndFromNormalEquations) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::MatrixXd phi(60, kParameterCount);
  for (int i = 0; i < phi.rows(); ++i) {
    for (int j = 0; j < kParameterCount; ++j) phi(i, j) = gauss(rng);
  }
  phi.col(5) = 3.0 * phi.col(4) - 2.0 * phi.col(3);  // x_r'' a combination of x_r, x_r'
  Eigen::VectorXd y = phi * Vector8::LinSpaced(0.1, 0.8);
  for (int i = 0; i < y.size(); ++i) y(i) += 0.01 * gauss(rng);
  const RegressionProblem rows = test::problem_from_rows(phi, y, 1e-3);
  const RegressionProblem normal = RegressionProblem::from_normal_equations(rows.normal_equations());
  // The attainable minimum is that of the problem without the dependent column.
  Eigen::MatrixXd phi7(phi.rows(), 7);
  phi7 << phi.leftCols(5), phi.rightCols(2);
  const double expected = 0.5 * (y - phi7 * phi7.colPivHouseholderQr().solve(y)).squaredNorm();
  for (const RegressionProblem* p : {&rows, &normal}) {
    const Solution s = solve(*p, Method::Ls, default_bounds(1e-3));
    EXPECT_THAT(s.warnings, testing::Contains(testing::HasSubstr("linearly dependent")));
    EXPECT_NEAR(s.objective, expected, 1e-6 * expected);
    int zeros = 0;
    for (int j = 3; j < 6; ++j) zeros += s.theta(j) == 0.0 ? 1 : 0;
    EXPECT_EQ(zeros, 1);
  }
}

TEST(SolverReduction, NothingDependsOnLengthUnits) {
  // The same capture in mm and in m (x 1000 on every length): theta1, beta and the poles are
  // unit-free, delta scales with the length unit, f with its square.
  const ModelCoefficients c = test::thesis_pid_drive();
  const RegressionProblem mm = test::thesis_like_problem(c, 21, 1e-3, 0.0, 1.0, 30);
  const RegressionProblem m = test::thesis_like_problem(c, 21, 1e-3, 0.0, 1e-3, 30);
  const detail::ReducedProblem rmm(mm), rm(m);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(rmm.theta1_scale()(k), rm.theta1_scale()(k), 1e-12 * rmm.theta1_scale()(k));
  EXPECT_TRUE(rmm.a().isApprox(rm.a(), 1e-9));
  EXPECT_TRUE(rmm.b().isApprox(rm.b(), 1e-9));
  EXPECT_NEAR(rmm.c(), rm.c(), 1e-9 * rmm.c());
  const Solution smm = solve(mm, Method::Ls, default_bounds(1e-3));
  const Solution sm = solve(m, Method::Ls, default_bounds(1e-3));
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(sm.theta(j), smm.theta(j), 1e-7 * std::abs(smm.theta(j))) << j;
  for (int j = 6; j < 8; ++j) EXPECT_NEAR(1e3 * sm.theta(j), smm.theta(j), 1e-7 * std::abs(smm.theta(j))) << j;
  EXPECT_NEAR(1e6 * sm.objective, smm.objective, 1e-9 * smm.objective);
}

}  // namespace
}  // namespace servotwin::rapid
