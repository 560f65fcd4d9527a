// RegressionProblem: factor, normal equations, objective, merge and the re-factorization of
// imported normal equations, checked against dense computations on explicit matrices (Eigen's
// own products and its column-pivoting QR as the independent reference).

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/rapid/regression.hpp"

namespace servotwin::rapid {
namespace {

using Augmented = Eigen::Matrix<double, Eigen::Dynamic, kParameterCount + 1>;

/// A random [Phi y] whose columns have very different magnitudes (as e_i, velocities,
/// accelerations and 0/1 friction columns do).
Augmented random_rows(int rows, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  Augmented a(rows, kParameterCount + 1);
  const double magnitude[] = {1e-3, 1e2, 1e4, 10.0, 1e2, 1e4, 1.0, 1.0, 10.0};
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j <= kParameterCount; ++j) a(i, j) = magnitude[j] * normal(rng);
  }
  return a;
}

/// Factor of [Phi y] by Eigen's Householder QR (upper 9 x 9 block, rows sign-normalized).
Matrix9 reference_factor(const Augmented& a) {
  Eigen::HouseholderQR<Augmented> qr(a);
  Matrix9 r = qr.matrixQR().topRows<kParameterCount + 1>().triangularView<Eigen::Upper>();
  for (int i = 0; i <= kParameterCount; ++i) {
    if (r(i, i) < 0.0) r.row(i) *= -1.0;
  }
  return r;
}

/// max |a_ij - b_ij| / sqrt(b_ii b_jj): the natural relative error of a Gram matrix entry.
double gram_error(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    for (Eigen::Index j = 0; j < a.cols(); ++j) {
      worst = std::max(worst, std::abs(a(i, j) - b(i, j)) / std::sqrt(b(i, i) * b(j, j)));
    }
  }
  return worst;
}

Eigen::MatrixXd gram(const NormalEquations& ne) {
  Eigen::MatrixXd g(kParameterCount + 1, kParameterCount + 1);
  g.topLeftCorner(kParameterCount, kParameterCount) = ne.P;
  g.topRightCorner(kParameterCount, 1) = ne.R;
  g.bottomLeftCorner(1, kParameterCount) = ne.R.transpose();
  g(kParameterCount, kParameterCount) = ne.gamma;
  return g;
}

TEST(RegressionProblem, NormalEquationsAreTheGramMatrixOfTheRows) {
  const Augmented a = random_rows(500, 1);
  const RegressionProblem problem(reference_factor(a), 500, 0.001);
  const NormalEquations ne = problem.normal_equations();
  const Eigen::MatrixXd dense = a.transpose() * a;
  EXPECT_LT(gram_error(gram(ne), dense), 1e-14);
  EXPECT_EQ(ne.P, ne.P.transpose());  // exactly symmetric
  EXPECT_EQ(ne.n, 500u);
  EXPECT_EQ(ne.ts, 0.001);
}

TEST(RegressionProblem, ObjectiveEqualsHalfTheSquaredResidual) {
  const Augmented a = random_rows(300, 2);
  const RegressionProblem problem(reference_factor(a), 300, 0.001);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 5; ++trial) {
    Vector8 theta;
    for (int j = 0; j < kParameterCount; ++j) theta(j) = normal(rng);
    const Eigen::VectorXd residual = a.col(kParameterCount) - a.leftCols<kParameterCount>() * theta;
    const double expected = 0.5 * residual.squaredNorm();
    EXPECT_NEAR(problem.objective(theta), expected, 1e-12 * expected);
  }
  // At the least-squares solution the objective is the residual of Eigen's pivoting QR.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> lsq(a.leftCols<kParameterCount>());
  const Vector8 theta = lsq.solve(Eigen::VectorXd(a.col(kParameterCount)));
  const double expected = 0.5 * (a.col(kParameterCount) - a.leftCols<kParameterCount>() * theta).squaredNorm();
  EXPECT_NEAR(problem.objective(theta), expected, 1e-9 * expected);
  // ... and it is the smallest: 1/2 U(8,8)^2.
  EXPECT_NEAR(expected, 0.5 * problem.factor()(8, 8) * problem.factor()(8, 8), 1e-9 * expected);
}

TEST(RegressionProblem, ConstructorNormalizesTheDiagonalSign) {
  Matrix9 u = reference_factor(random_rows(50, 4));
  u.row(3) *= -1.0;
  u.row(8) *= -1.0;
  const RegressionProblem problem(u, 50, 0.002);
  EXPECT_TRUE((problem.factor().diagonal().array() >= 0.0).all());
  EXPECT_EQ((problem.factor().transpose() * problem.factor()).eval(), (u.transpose() * u).eval());
}

TEST(RegressionProblem, MergeEqualsTheFactorOfStackedRows) {
  const Augmented a = random_rows(200, 5);
  const Augmented b = random_rows(150, 6) * 1e3;  // very different magnitude
  RegressionProblem merged(reference_factor(a), 200, 0.001);
  merged.merge(RegressionProblem(reference_factor(b), 150, 0.001 * (1.0 + 1e-12)));
  Augmented stacked(350, kParameterCount + 1);
  stacked << a, b;
  const Matrix9 expected = reference_factor(stacked);
  EXPECT_LT((merged.factor() - expected).norm(), 1e-13 * expected.norm());
  EXPECT_LT(gram_error(gram(merged.normal_equations()), stacked.transpose() * stacked), 1e-14);
  EXPECT_EQ(merged.samples(), 350u);
}

TEST(RegressionProblem, MergeWithEmptyProblems) {
  const RegressionProblem a(reference_factor(random_rows(40, 7)), 40, 0.001);
  RegressionProblem empty;
  empty.merge(a);
  EXPECT_EQ(empty.factor(), a.factor());
  EXPECT_EQ(empty.ts(), 0.001);
  RegressionProblem copy = a;
  copy.merge(RegressionProblem{});
  EXPECT_EQ(copy.factor(), a.factor());
  EXPECT_EQ(copy.samples(), 40u);
}

TEST(RegressionProblem, MergeRejectsDifferentSamplePeriods) {
  RegressionProblem a(reference_factor(random_rows(40, 8)), 40, 0.001);
  const RegressionProblem b(reference_factor(random_rows(40, 9)), 40, 0.001 * (1.0 + 1e-8));
  try {
    a.merge(b);
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "Ts");
    EXPECT_NE(std::string(e.what()).find("different sample periods"), std::string::npos);
  }
  EXPECT_EQ(a.samples(), 40u);  // unchanged
}

TEST(RegressionProblem, NormalEquationsRoundTrip) {
  const Augmented a = random_rows(400, 10);
  const RegressionProblem problem(reference_factor(a), 400, 0.001);
  const NormalEquations ne = problem.normal_equations();
  const RegressionProblem back = RegressionProblem::from_normal_equations(ne);
  EXPECT_EQ(back.samples(), 400u);
  EXPECT_EQ(back.ts(), 0.001);
  EXPECT_LT(gram_error(gram(back.normal_equations()), gram(ne)), 1e-14);
  // The canonical factor (diagonal >= 0) is unique for a full-rank matrix.
  EXPECT_LT((back.factor() - problem.factor()).norm(), 1e-10 * problem.factor().norm());
}

TEST(RegressionProblem, NormalEquationsOfSemidefiniteData) {
  // The negative-direction column never occurs (all zero) and x_r duplicates x: rank 7 of 8.
  Augmented a = random_rows(300, 11);
  a.col(7).setZero();
  a.col(3) = a.col(8);
  const RegressionProblem problem(reference_factor(a), 300, 0.001);
  const NormalEquations ne = problem.normal_equations();
  const RegressionProblem back = RegressionProblem::from_normal_equations(ne);
  EXPECT_LT(gram_error(gram(back.normal_equations()).topLeftCorner(7, 7), gram(ne).topLeftCorner(7, 7)), 1e-14);
  EXPECT_EQ(back.normal_equations().P.row(7).norm(), 0.0);
  // The exact fit y = x_r has zero objective in both.
  Vector8 theta = Vector8::Zero();
  theta(3) = 1.0;
  EXPECT_LT(back.objective(theta), 1e-20 * ne.gamma);
}

NormalEquations valid_statistics() {
  return RegressionProblem(reference_factor(random_rows(100, 12)), 100, 0.001).normal_equations();
}

void expect_field_error(const NormalEquations& ne, const std::string& field, const std::string& text) {
  try {
    (void)RegressionProblem::from_normal_equations(ne);
    FAIL() << "expected InputError for " << field;
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, field) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(RegressionProblem, FromNormalEquationsRejectsBadInput) {
  NormalEquations ne = valid_statistics();
  ne.P(2, 5) *= 1.001;
  expect_field_error(ne, "P", "not symmetric");
  ne = valid_statistics();
  ne.P(1, 1) = std::nan("");
  expect_field_error(ne, "P", "not finite");
  ne = valid_statistics();
  ne.R(4) = INFINITY;
  expect_field_error(ne, "R", "not finite");
  ne = valid_statistics();
  ne.gamma = -1.0;
  expect_field_error(ne, "Gamma", "negative");
  ne = valid_statistics();
  ne.n = 0;
  expect_field_error(ne, "N", "at least 1");
  ne = valid_statistics();
  ne.ts = 0.0;
  expect_field_error(ne, "Ts", "positive");
  ne = valid_statistics();
  ne.ts = std::nan("");
  expect_field_error(ne, "Ts", "positive");
  // |P_01| > sqrt(P_00 P_11): indefinite.
  ne = valid_statistics();
  ne.P(0, 1) = ne.P(1, 0) = 1.5 * std::sqrt(ne.P(0, 0) * ne.P(1, 1));
  expect_field_error(ne, "P", "indefinite");
  // Gamma below the least-squares fit R^T P^-1 R.
  ne = valid_statistics();
  ne.gamma = 0.5 * ne.R.dot(ne.P.ldlt().solve(ne.R));
  expect_field_error(ne, "Gamma", "indefinite");
  // A zero column with a nonzero correlation.
  ne = valid_statistics();
  ne.P.row(6).setZero();
  ne.P.col(6).setZero();
  ne.R(6) = 1.0;
  expect_field_error(ne, "R", "indefinite");
}

TEST(RegressionProblem, AGammaBelowTheLeastSquaresFitIsRaisedWithAWarning) {
  // Issue 27 §3.17: statistics printed with two decimals (the thesis's appendix) can put Gamma below
  // R^T P^+ R. The minimizer of 1/2 theta^T P theta - R^T theta does not depend on Gamma: with a
  // warnings list the problem is solved, the objective's minimizer is that of the true statistics
  // (reference: P^-1 R by LDL^T), and the objective at it is ~0 (Gamma raised to the least value).
  const NormalEquations truth = valid_statistics();
  NormalEquations rounded = truth;
  const Vector8 minimizer = truth.P.ldlt().solve(truth.R);
  rounded.gamma = 0.5 * truth.R.dot(minimizer);
  std::vector<std::string> warnings;
  const RegressionProblem repaired = RegressionProblem::from_normal_equations(rounded, &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings.front().find("objective shifted"), std::string::npos) << warnings.front();
  const NormalEquations back = repaired.normal_equations();
  const Vector8 again = back.P.ldlt().solve(back.R);
  EXPECT_LT((again - minimizer).norm(), 1e-8 * minimizer.norm());
  EXPECT_LT(repaired.objective(minimizer), 1e-6 * truth.gamma);
  // Without a warnings list the strict reading stays; an R outside P's range has no minimizer.
  EXPECT_THROW((void)RegressionProblem::from_normal_equations(rounded), core::InputError);
  NormalEquations outside = truth;
  outside.P.row(6).setZero();
  outside.P.col(6).setZero();
  outside.R(6) = 1.0;
  try {
    (void)RegressionProblem::from_normal_equations(outside, &warnings);
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "R") << e.what();
  }
}

TEST(RegressionProblem, ConstructorRejectsBadFactors) {
  Matrix9 u = reference_factor(random_rows(30, 13));
  EXPECT_THROW(RegressionProblem(u, 30, -0.001), core::InputError);
  Matrix9 lower = u;
  lower(5, 2) = 1.0;
  EXPECT_THROW(RegressionProblem(lower, 30, 0.001), core::InputError);
  Matrix9 nan = u;
  nan(0, 4) = std::nan("");
  EXPECT_THROW(RegressionProblem(nan, 30, 0.001), core::InputError);
  EXPECT_THROW(RegressionProblem(u, 0, 0.001), core::InputError);
  EXPECT_NO_THROW(RegressionProblem(Matrix9::Zero(), 0, 0.001));
}

}  // namespace
}  // namespace servotwin::rapid
