#include "servotwin/core/model_reduction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "servotwin/core/riccati.hpp"

namespace servotwin::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

void check_system(const StateSpace& s) {
  const Eigen::Index n = s.A.rows();
  if (s.A.cols() != n || s.B.rows() != n || s.C.cols() != n || s.D.rows() != s.C.rows() || s.D.cols() != s.B.cols())
    throw std::invalid_argument("model reduction: inconsistent state-space shapes");
  if (!s.A.allFinite() || !s.B.allFinite() || !s.C.allFinite() || !s.D.allFinite())
    throw std::invalid_argument("model reduction: non-finite state-space matrices");
  if (n == 0) return;
  const Eigen::VectorXcd poles = s.A.eigenvalues();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(poles[i].real() < 0.0))
      throw std::domain_error("model reduction: the system has a pole with Re >= 0 (no Gramians); reduce its stable part");
  }
}

/// L with P = L L^T for a symmetric positive semidefinite P (eigenvalues below rounding clipped).
Eigen::MatrixXd psd_factor(const Eigen::MatrixXd& p) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (p + p.transpose()));
  Eigen::VectorXd values = eig.eigenvalues();
  double largest = 0.0;
  for (Eigen::Index i = 0; i < values.size(); ++i) largest = std::max(largest, std::abs(values[i]));
  const double floor = static_cast<double>(p.rows()) * kEps * largest;
  for (Eigen::Index i = 0; i < values.size(); ++i) values[i] = values[i] > floor ? std::sqrt(values[i]) : 0.0;
  return eig.eigenvectors() * values.asDiagonal();
}

struct SquareRoot {
  Eigen::MatrixXd lc, lo;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd;
};

SquareRoot square_root(const StateSpace& sys) {
  // A Wc + Wc A^T + B B^T = 0 and A^T Wo + Wo A + C^T C = 0 (solve_lyapunov solves A^T X + X A + Q = 0).
  const Eigen::MatrixXd wc = solve_lyapunov(sys.A.transpose(), sys.B * sys.B.transpose());
  const Eigen::MatrixXd wo = solve_lyapunov(sys.A, sys.C.transpose() * sys.C);
  SquareRoot r{psd_factor(wc), psd_factor(wo), {}};
  r.svd.compute(r.lo.transpose() * r.lc, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return r;
}

}  // namespace

Eigen::VectorXd hankel_singular_values(const StateSpace& sys) {
  check_system(sys);
  if (sys.A.rows() == 0) return {};
  return square_root(sys).svd.singularValues();
}

BalancedTruncation balanced_truncation(const StateSpace& sys, Eigen::Index order) {
  check_system(sys);
  const Eigen::Index n = sys.A.rows();
  if (order < 0 || order > n) throw std::invalid_argument("balanced_truncation: order out of range");
  BalancedTruncation out;
  if (n == 0) {
    out.reduced = sys;
    return out;
  }
  const SquareRoot sr = square_root(sys);
  out.hankel = sr.svd.singularValues();
  // Retained directions must be observable and controllable (sigma > 0), else the projection
  // would divide by zero: such states contribute nothing and are dropped with the others.
  const double floor = static_cast<double>(n) * kEps * out.hankel[0];
  Eigen::Index kept = order;
  while (kept > 0 && !(out.hankel[kept - 1] > floor)) --kept;
  const Eigen::VectorXd inv_sqrt = out.hankel.head(kept).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd t = sr.lc * sr.svd.matrixV().leftCols(kept) * inv_sqrt.asDiagonal();             // n x r
  const Eigen::MatrixXd ti = inv_sqrt.asDiagonal() * sr.svd.matrixU().leftCols(kept).transpose() * sr.lo.transpose();  // r x n
  out.reduced.A = ti * sys.A * t;
  out.reduced.B = ti * sys.B;
  out.reduced.C = sys.C * t;
  out.reduced.D = sys.D;
  // Glover's bound counts each distinct discarded value once.
  double bound = 0.0;
  for (Eigen::Index i = kept; i < n; ++i) {
    const bool repeated = i > kept && std::abs(out.hankel[i] - out.hankel[i - 1]) <= 1e-10 * out.hankel[0];
    if (!repeated) bound += out.hankel[i];
  }
  out.error_bound = 2.0 * bound;
  return out;
}

}  // namespace servotwin::core
