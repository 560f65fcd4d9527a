// The reduction shared by all solvers: column equilibration of [Phi y], elimination of
// theta2 = (beta_0, beta_1, beta_2, delta+, delta-) by a column-pivoted QR (Eq. 4.9 without forming
// Phi2^T Phi2), and the remaining convex quadratic in theta1 in square-root form. Also the thesis's
// Eq. 4.11-4.12 matrices computed literally from normal equations, which tests compare against.

#include <cmath>
#include <cstdio>
#include <string>

#include "servotwin/rapid/solver_detail.hpp"

namespace servotwin::rapid::detail {

namespace {

constexpr std::array<const char*, kParameterCount> kParameterNames{"alpha_i", "alpha_1", "alpha_2", "beta_0",
                                                                   "beta_1",  "beta_2",  "delta+",  "delta-"};

std::string format_pivot(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1e", v);
  return buf;
}

std::string dependency_note(int column, double column_norm, double pivot) {
  const std::string regressor = std::string(kRegressorNames[static_cast<std::size_t>(column)]);
  const std::string parameter = kParameterNames[static_cast<std::size_t>(column)];
  if (column_norm == 0.0) return "regressor '" + regressor + "' is zero: " + parameter + " not identifiable, fixed at 0";
  return "regressor '" + regressor + "' is linearly dependent on the others (relative pivot " + format_pivot(pivot) +
         " < " + format_pivot(kRankTolerance) + "): " + parameter + " not identifiable, fixed at 0";
}

}  // namespace

ReducedProblem::ReducedProblem(const RegressionProblem& problem) {
  const Matrix9& u = problem.factor();
  // Equilibrate: every column of [Phi y] to unit norm. Lengths scale the columns of e_i, x, x_r and
  // their derivatives and y alike, so the equilibrated problem, and everything below, is unit-free.
  Matrix9 w = Matrix9::Zero();
  for (int j = 0; j < kParameterCount + 1; ++j) {
    const double norm = u.col(j).stableNorm();
    if (j < kParameterCount) column_norm_[static_cast<std::size_t>(j)] = norm;
    if (norm > 0.0) w.col(j) = u.col(j) / norm;
    if (j == kParameterCount && norm > 0.0) y_norm_ = norm;
  }
  y2_ = y_norm_ * y_norm_;
  for (int j = 0; j < 3; ++j) s1_(j) = column_norm_[static_cast<std::size_t>(j)] / y_norm_;

  // theta2 block: pivoted QR; trailing pivots below the tolerance are dependent regressors.
  const Eigen::Matrix<double, 9, 5> w2 = w.block<9, 5>(0, 3);
  const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 9, 5>> qr(w2);
  const auto& packed = qr.matrixQR();
  rank2_ = 0;
  while (rank2_ < 5 && std::abs(packed(rank2_, rank2_)) > kRankTolerance) ++rank2_;
  for (int k = 0; k < 5; ++k) perm2_[static_cast<std::size_t>(k)] = qr.colsPermutation().indices()(k);
  kept2_.fill(false);
  for (int k = 0; k < rank2_; ++k) kept2_[static_cast<std::size_t>(perm2_[static_cast<std::size_t>(k)])] = true;
  for (int k = rank2_; k < 5; ++k) {
    const int column = 3 + perm2_[static_cast<std::size_t>(k)];
    warnings_.push_back(
        dependency_note(column, column_norm_[static_cast<std::size_t>(column)], std::abs(packed(k, k))));
  }
  for (int j = 0; j < 3; ++j) {
    if (column_norm_[static_cast<std::size_t>(j)] == 0.0) {
      warnings_.push_back("regressor '" + std::string(kRegressorNames[static_cast<std::size_t>(j)]) + "' is zero: " +
                          kParameterNames[static_cast<std::size_t>(j)] + " does not affect the fit");
    }
  }
  r2_.setZero();
  r2_.topLeftCorner(rank2_, rank2_) = packed.topLeftCorner(rank2_, rank2_).triangularView<Eigen::Upper>();

  Eigen::Matrix<double, 9, 4> m;
  m.leftCols<3>() = w.leftCols<3>();
  m.col(3) = w.col(kParameterCount);
  m.applyOnTheLeft(qr.householderQ().adjoint());
  c1_.setZero();
  ty_.setZero();
  c1_.topRows(rank2_) = m.topLeftCorner(rank2_, 3);
  ty_.head(rank2_) = m.block(0, 3, rank2_, 1);

  // What theta2 cannot absorb: rows rank2..8, triangularized.
  const Eigen::Matrix<double, Eigen::Dynamic, 4, 0, 9, 4> z = m.bottomRows(9 - rank2_);
  const Eigen::HouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, 4, 0, 9, 4>> zqr(z);
  const Eigen::Matrix4d s = zqr.matrixQR().topRows<4>().triangularView<Eigen::Upper>();
  a_ = s.topLeftCorner<3, 3>();
  b_ = s.block<3, 1>(0, 3);
  c_ = std::abs(s(3, 3));
}

double ReducedProblem::excess(const Eigen::Vector3d& theta1) const noexcept {
  return 0.5 * (a_ * s1_.cwiseProduct(theta1) - b_).squaredNorm();
}

double ReducedProblem::objective(const Eigen::Vector3d& theta1) const noexcept {
  return y2_ * (excess(theta1) + 0.5 * c_ * c_);
}

Eigen::Vector3d ReducedProblem::objective_gradient(const Eigen::Vector3d& theta1) const noexcept {
  const Eigen::Vector3d r = a_ * s1_.cwiseProduct(theta1) - b_;
  return y2_ * s1_.cwiseProduct(a_.transpose() * r);
}

Vector8 ReducedProblem::theta(const Eigen::Vector3d& theta1) const {
  Vector8 theta = Vector8::Zero();
  theta.head<3>() = theta1;
  if (rank2_ > 0) {
    const Eigen::Vector3d t1 = s1_.cwiseProduct(theta1);
    const Eigen::VectorXd rhs = ty_.head(rank2_) - c1_.topRows(rank2_) * t1;
    const Eigen::VectorXd pivoted =
        r2_.topLeftCorner(rank2_, rank2_).triangularView<Eigen::Upper>().solve(rhs);
    for (int k = 0; k < rank2_; ++k) {
      const int column = 3 + perm2_[static_cast<std::size_t>(k)];
      theta(column) = y_norm_ * pivoted(k) / column_norm_[static_cast<std::size_t>(column)];
    }
  }
  return theta;
}

Eigen::Matrix4d ReducedProblem::quadratic_form() const {
  Eigen::Matrix4d l = Eigen::Matrix4d::Zero();
  l.block<3, 1>(0, 0) = b_;
  l.block<3, 3>(0, 1) = -a_ * s1_.asDiagonal();
  l(3, 0) = c_;
  return y2_ * l.transpose() * l;
}

Vector8 ReducedProblem::least_squares() const {
  // Rank-revealing solve of A theta1~ = b: the columns of A are what is left of unit-norm columns
  // after projecting out theta2's and the preceding ones, so the pivot tolerance is the same
  // relative dependency measure as for theta2.
  const Eigen::ColPivHouseholderQR<Eigen::Matrix3d> qr(a_);
  const auto& packed = qr.matrixQR();
  int rank = 0;
  while (rank < 3 && std::abs(packed(rank, rank)) > kRankTolerance) ++rank;
  Eigen::Vector3d rhs = b_;
  rhs.applyOnTheLeft(qr.householderQ().adjoint());
  Eigen::Vector3d basic = Eigen::Vector3d::Zero();
  if (rank > 0) {
    basic.head(rank) = packed.topLeftCorner(rank, rank).triangularView<Eigen::Upper>().solve(rhs.head(rank));
  }
  Eigen::Vector3d t1 = qr.colsPermutation() * basic;
  Eigen::Vector3d theta1 = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) theta1(j) = s1_(j) > 0.0 ? t1(j) / s1_(j) : 0.0;
  return theta(theta1);
}

std::vector<std::string> ReducedProblem::least_squares_notes() const {
  const Eigen::ColPivHouseholderQR<Eigen::Matrix3d> qr(a_);
  const auto& packed = qr.matrixQR();
  std::vector<std::string> notes;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(packed(k, k)) > kRankTolerance) continue;
    const int column = qr.colsPermutation().indices()(k);
    if (column_norm_[static_cast<std::size_t>(column)] == 0.0) continue;  // already reported as zero
    notes.push_back(dependency_note(column, 1.0, std::abs(packed(k, k))));
  }
  return notes;
}

ThesisQuadraticForm thesis_quadratic_form(const NormalEquations& ne) {
  const Eigen::Matrix<double, 5, 5> p22 = ne.P.block<5, 5>(3, 3);
  const Eigen::Matrix<double, 5, 3> p21 = ne.P.block<5, 3>(3, 0);
  const Eigen::Matrix<double, 5, 1> r2 = ne.R.tail<5>();
  const Eigen::FullPivLU<Eigen::Matrix<double, 5, 5>> lu(p22);
  ThesisQuadraticForm form;
  form.t.setZero();
  form.t.block<3, 3>(0, 1).setIdentity();
  form.t.block<5, 1>(3, 0) = lu.solve(r2);   // R*
  form.t.block<5, 3>(3, 1) = -lu.solve(p21);  // -P*
  form.a = form.t.transpose() * ne.P * form.t;
  form.b = -2.0 * ne.R.transpose() * form.t;
  form.gamma = ne.gamma;
  return form;
}

double evaluate(const ThesisQuadraticForm& form, const Eigen::Vector3d& theta1) noexcept {
  Eigen::Vector4d mu;
  mu << 1.0, theta1;
  return 0.5 * (mu.dot(form.a * mu) + form.b.dot(mu) + form.gamma);
}

}  // namespace servotwin::rapid::detail
