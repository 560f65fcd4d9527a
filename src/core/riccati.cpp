#include "servotwin/core/riccati.hpp"

#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

namespace servotwin::core {

namespace {

using Complex = std::complex<double>;

void require_shape(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument("solve_care: " + message);
}

double symmetry_defect(const Eigen::MatrixXd& m) {
  const double scale = std::max(m.norm(), std::numeric_limits<double>::min());
  return (m - m.transpose()).norm() / scale;
}

void check_care_inputs(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd& q,
                       const Eigen::MatrixXd& r) {
  const Eigen::Index n = a.rows();
  require_shape(n > 0 && a.cols() == n, "A must be square and non-empty");
  require_shape(b.rows() == n && b.cols() > 0, "B must have as many rows as A and at least one column");
  require_shape(q.rows() == n && q.cols() == n, "Q must be n x n");
  require_shape(r.rows() == b.cols() && r.cols() == b.cols(), "R must be m x m (m = columns of B)");
  require_shape(a.allFinite() && b.allFinite() && q.allFinite() && r.allFinite(), "matrices must be finite");
  require_shape(symmetry_defect(q) <= 1e-12, "Q must be symmetric");
  require_shape(symmetry_defect(r) <= 1e-12, "R must be symmetric");
  const Eigen::LLT<Eigen::MatrixXd> llt(r);
  require_shape(llt.info() == Eigen::Success, "R must be positive definite");
}

/// Res(X) = A^T X + X A - X G X + Q and the scale it is judged against.
struct Residual {
  Eigen::MatrixXd value;
  double relative = 0.0;
};

Residual care_residual(const Eigen::MatrixXd& a, const Eigen::MatrixXd& g, const Eigen::MatrixXd& q,
                       const Eigen::MatrixXd& x) {
  const Eigen::MatrixXd linear = a.transpose() * x + x * a;
  const Eigen::MatrixXd quadratic = x * g * x;
  Residual res;
  res.value = linear - quadratic + q;
  const double scale = q.norm() + linear.norm() + quadratic.norm();
  res.relative = scale > 0.0 ? res.value.norm() / scale : res.value.norm();
  return res;
}

/// Matrix sign function by the scaled Newton iteration Z <- (Z/c + c Z^-1)/2, c = |det Z|^(1/N).
/// Converged when the relative change falls below 1e-13, or when it has reached its rounding floor:
/// below 1e-10 (the quadratic phase has ended) and no longer halving (Higham, Functions of
/// Matrices, sec. 5.8); ill-conditioned Hamiltonians (H-infinity weights) stagnate near 1e-12,
/// and the Newton–Kleinman refinement of the caller restores the accuracy. Returns false when the
/// iteration does not converge (eigenvalues on or near the imaginary axis).
bool matrix_sign(Eigen::MatrixXd& z, int& iterations) {
  const Eigen::Index size = z.rows();
  constexpr int kMaxIterations = 100;
  double previous_change = std::numeric_limits<double>::infinity();
  for (iterations = 0; iterations < kMaxIterations; ++iterations) {
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(z);
    // log|det Z| summed from the LU diagonal: det itself over/underflows for large N.
    double log_det = 0.0;
    for (Eigen::Index i = 0; i < size; ++i) log_det += std::log(std::abs(lu.matrixLU()(i, i)));
    if (!std::isfinite(log_det)) return false;
    const double c = std::exp(log_det / static_cast<double>(size));
    const Eigen::MatrixXd next = 0.5 * (z / c + c * lu.inverse());
    if (!next.allFinite()) return false;
    const double change = (next - z).lpNorm<1>() / next.lpNorm<1>();
    z = next;
    const bool at_rounding_floor = previous_change <= 1e-10 && change > 0.5 * previous_change;
    if (change <= 1e-13 || at_rounding_floor) {
      ++iterations;
      return true;
    }
    previous_change = change;
  }
  return false;
}

bool is_hurwitz(const Eigen::MatrixXd& m) {
  const Eigen::ComplexEigenSolver<Eigen::MatrixXd> eig(m, false);
  if (eig.info() != Eigen::Success) return false;
  return (eig.eigenvalues().real().array() < 0.0).all();
}

}  // namespace

Eigen::MatrixXd solve_lyapunov(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Q) {
  const Eigen::Index n = A.rows();
  if (n == 0 || A.cols() != n || Q.rows() != n || Q.cols() != n)
    throw std::invalid_argument("solve_lyapunov: A and Q must be square of the same size");
  if (!A.allFinite() || !Q.allFinite()) throw std::invalid_argument("solve_lyapunov: matrices must be finite");
  // A = U T U^*, so A^T = A^* = U T^* U^* (A real) and with Y = U^* X U: T^* Y + Y T = -U^* Q U.
  const Eigen::ComplexSchur<Eigen::MatrixXd> schur(A);
  if (schur.info() != Eigen::Success) throw std::domain_error("solve_lyapunov: Schur decomposition failed");
  const Eigen::MatrixXcd& u = schur.matrixU();
  const Eigen::MatrixXcd& t = schur.matrixT();
  const Eigen::MatrixXcd rhs = -(u.adjoint() * Q.cast<Complex>() * u);
  const Eigen::MatrixXcd t_adjoint = t.adjoint();  // lower triangular
  Eigen::MatrixXcd y(n, n);
  const double scale = std::max(t.norm(), std::numeric_limits<double>::min());
  for (Eigen::Index j = 0; j < n; ++j) {
    Eigen::VectorXcd column = rhs.col(j);
    for (Eigen::Index l = 0; l < j; ++l) column -= t(l, j) * y.col(l);
    Eigen::MatrixXcd system = t_adjoint;
    system.diagonal().array() += t(j, j);
    for (Eigen::Index i = 0; i < n; ++i)
      if (std::abs(system(i, i)) <= 1e-14 * scale)
        throw std::domain_error("solve_lyapunov: A has eigenvalues l_i, l_j with conj(l_i) + l_j = 0; no unique solution");
    y.col(j) = system.triangularView<Eigen::Lower>().solve(column);
  }
  Eigen::MatrixXd x = (u * y * u.adjoint()).real();
  if (symmetry_defect(Q) <= 1e-12) x = 0.5 * (x + x.transpose()).eval();
  return x;
}

namespace {

/// The stabilizing solution of A^T X + X A - X G X + Q = 0 for symmetric G and Q of any inertia:
/// the sign function of the Hamiltonian, then Newton–Kleinman refinement. `who` names the caller
/// in the error messages.
Eigen::MatrixXd stabilizing_solution(const Eigen::MatrixXd& a, const Eigen::MatrixXd& g, const Eigen::MatrixXd& q,
                                     CareReport* report, const std::string& who, double residual_tolerance = 1e-8) {
  const Eigen::Index n = a.rows();
  CareReport diag;
  // Q = 0 with A Hurwitz: X = 0 is the (unique) stabilizing solution, which the sign function
  // would only find up to rounding noise that no relative residual can judge.
  if (q.isZero(0.0) && is_hurwitz(a)) {
    if (report != nullptr) *report = diag;
    return Eigen::MatrixXd::Zero(n, n);
  }
  Eigen::MatrixXd z(2 * n, 2 * n);
  z << a, -g, -q, -a.transpose();
  if (!matrix_sign(z, diag.sign_iterations))
    throw std::domain_error(who +
                            ": the Hamiltonian has eigenvalues on the imaginary axis; no stabilizing solution "
                            "((A, B) not stabilizable or (Q, A) not detectable)");
  // sign(H) [I; X] = -[I; X]  =>  [W12; W22 + I] X = [-(I + W11); -W21].
  Eigen::MatrixXd lhs(2 * n, n), rhs(2 * n, n);
  lhs << z.topRightCorner(n, n), z.bottomRightCorner(n, n) + Eigen::MatrixXd::Identity(n, n);
  rhs << -(z.topLeftCorner(n, n) + Eigen::MatrixXd::Identity(n, n)), -z.bottomLeftCorner(n, n);
  Eigen::MatrixXd x = lhs.colPivHouseholderQr().solve(rhs);
  x = 0.5 * (x + x.transpose()).eval();

  // Newton–Kleinman on the residual: (A - G X)^T D + D (A - G X) = -Res(X), X <- X + D.
  Residual res = care_residual(a, g, q, x);
  constexpr int kMaxRefinements = 4;
  for (int step = 0; step < kMaxRefinements && res.relative > 1e-15; ++step) {
    const Eigen::MatrixXd closed = a - g * x;
    Eigen::MatrixXd candidate;
    try {
      candidate = x + solve_lyapunov(closed, res.value);
    } catch (const std::domain_error&) {
      break;  // closed loop not yet stabilizing: keep the sign-function solution
    }
    Residual next = care_residual(a, g, q, candidate);
    if (!(next.relative < res.relative)) break;
    x = 0.5 * (candidate + candidate.transpose());
    res = care_residual(a, g, q, x);
    ++diag.refinement_steps;
  }
  diag.relative_residual = res.relative;
  if (!x.allFinite() || !is_hurwitz(a - g * x) || res.relative > residual_tolerance) {
    char residual[32];
    std::snprintf(residual, sizeof residual, "%.3g", res.relative);
    throw std::domain_error(who + ": no stabilizing solution found (relative residual " + residual + ")");
  }
  if (report != nullptr) *report = diag;
  return x;
}

}  // namespace

Eigen::MatrixXd solve_care(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Q,
                           const Eigen::MatrixXd& R, CareReport* report) {
  check_care_inputs(A, B, Q, R);
  const Eigen::MatrixXd q = 0.5 * (Q + Q.transpose());
  const Eigen::MatrixXd r_inv_bt = R.llt().solve(B.transpose());
  Eigen::MatrixXd g = B * r_inv_bt;
  g = 0.5 * (g + g.transpose()).eval();
  return stabilizing_solution(A, g, q, report, "solve_care");
}

Eigen::MatrixXd solve_care_indefinite(const Eigen::MatrixXd& A, const Eigen::MatrixXd& G, const Eigen::MatrixXd& Q,
                                      CareReport* report, double residual_tolerance) {
  const Eigen::Index n = A.rows();
  const auto require = [](bool condition, const std::string& message) {
    if (!condition) throw std::invalid_argument("solve_care_indefinite: " + message);
  };
  require(n > 0 && A.cols() == n, "A must be square and non-empty");
  require(G.rows() == n && G.cols() == n && Q.rows() == n && Q.cols() == n, "G and Q must be n x n");
  require(A.allFinite() && G.allFinite() && Q.allFinite(), "matrices must be finite");
  require(symmetry_defect(G) <= 1e-10 && symmetry_defect(Q) <= 1e-10, "G and Q must be symmetric");
  const Eigen::MatrixXd g = 0.5 * (G + G.transpose());
  const Eigen::MatrixXd q = 0.5 * (Q + Q.transpose());
  require(residual_tolerance >= 1e-14 && residual_tolerance <= 1e-2, "residual_tolerance must lie in [1e-14, 1e-2]");
  return stabilizing_solution(A, g, q, report, "solve_care_indefinite", residual_tolerance);
}

Eigen::MatrixXd solve_care_filter(const Eigen::MatrixXd& A, const Eigen::MatrixXd& C, const Eigen::MatrixXd& W,
                                  const Eigen::MatrixXd& V, CareReport* report) {
  return solve_care(A.transpose(), C.transpose(), W, V, report);
}

}  // namespace servotwin::core
