#include "servotwin/core/model_reduction.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>

#include "servotwin/core/riccati.hpp"

namespace servotwin::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

void check_shapes(const StateSpace& s) {
  const Eigen::Index n = s.A.rows();
  if (s.A.cols() != n || s.B.rows() != n || s.C.cols() != n || s.D.rows() != s.C.rows() || s.D.cols() != s.B.cols())
    throw std::invalid_argument("model reduction: inconsistent state-space shapes");
  if (!s.A.allFinite() || !s.B.allFinite() || !s.C.allFinite() || !s.D.allFinite())
    throw std::invalid_argument("model reduction: non-finite state-space matrices");
}

void check_system(const StateSpace& s) {
  check_shapes(s);
  const Eigen::Index n = s.A.rows();
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

/// Swaps the adjacent diagonal entries k, k+1 of the upper-triangular t by a unitary rotation,
/// accumulated into q (t = q^H a q stays true).
void swap_schur_entries(Eigen::MatrixXcd& t, Eigen::MatrixXcd& q, Eigen::Index k) {
  const std::complex<double> a = t(k, k), b = t(k + 1, k + 1), c = t(k, k + 1);
  // [c, b - a] is the eigenvector of [[a, c], [0, b]] for b: as the first column of the rotation
  // it moves b to the top.
  const double norm = std::hypot(std::abs(c), std::abs(b - a));
  if (norm == 0.0) return;  // equal entries, already decoupled: nothing to swap
  Eigen::Matrix2cd g;
  g << c / norm, -std::conj(b - a) / norm, (b - a) / norm, std::conj(c) / norm;
  t.middleRows(k, 2) = g.adjoint() * t.middleRows(k, 2);
  t.middleCols(k, 2) = t.middleCols(k, 2) * g;
  t(k + 1, k) = 0.0;
  q.middleCols(k, 2) = q.middleCols(k, 2) * g;
}

/// A real orthonormal basis (n x n) whose first `stable` columns span the invariant subspace of
/// the eigenvalues of a with Re < alpha.
Eigen::MatrixXd stable_first_basis(const Eigen::MatrixXd& a, double alpha, Eigen::Index& stable) {
  const Eigen::Index n = a.rows();
  Eigen::ComplexSchur<Eigen::MatrixXcd> schur(a.cast<std::complex<double>>());
  Eigen::MatrixXcd t = schur.matrixT(), q = schur.matrixU();
  // Bubble the stable eigenvalues to the front, keeping the order within each set.
  stable = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!(t(i, i).real() < alpha)) continue;
    for (Eigen::Index k = i; k > stable; --k) swap_schur_entries(t, q, k - 1);
    ++stable;
  }
  if (stable == 0 || stable == n) return Eigen::MatrixXd::Identity(n, n);
  // The subspace is real (closed under conjugation): its real basis from [Re Q1, Im Q1].
  Eigen::MatrixXd span(n, 2 * stable);
  span << q.leftCols(stable).real(), q.leftCols(stable).imag();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(span, Eigen::ComputeFullU);
  return svd.matrixU();
}

/// X with a11 X - X a22 + a12 = 0 (Kronecker form; the blocks are small).
Eigen::MatrixXd decoupling_solution(const Eigen::MatrixXd& a11, const Eigen::MatrixXd& a22, const Eigen::MatrixXd& a12) {
  const Eigen::Index n1 = a11.rows(), n2 = a22.rows();
  // vec(a11 X - X a22) = (I (x) a11 - a22^T (x) I) vec(X), column-major.
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n1 * n2, n1 * n2);
  for (Eigen::Index j = 0; j < n2; ++j) {
    k.block(j * n1, j * n1, n1, n1) += a11;
    for (Eigen::Index i = 0; i < n2; ++i) k.block(j * n1, i * n1, n1, n1).diagonal().array() -= a22(i, j);
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(k);
  if (lu.rank() < k.rows() || lu.rcond() < 1e3 * kEps)
    throw std::domain_error("stable_split: the stable and unstable poles are too close to separate");
  const Eigen::VectorXd x = lu.solve(-Eigen::Map<const Eigen::VectorXd>(a12.data(), a12.size()));
  return Eigen::Map<const Eigen::MatrixXd>(x.data(), n1, n2);
}

}  // namespace

StableSplit stable_split(const StateSpace& sys, double alpha) {
  check_shapes(sys);
  if (!std::isfinite(alpha)) throw std::invalid_argument("stable_split: the boundary must be finite");
  const Eigen::Index n = sys.A.rows(), p = sys.C.rows(), m = sys.B.cols();
  Eigen::Index ns = 0;
  const Eigen::MatrixXd w = n == 0 ? Eigen::MatrixXd() : stable_first_basis(sys.A, alpha, ns);
  const Eigen::Index nu = n - ns;
  const Eigen::MatrixXd a = n == 0 ? Eigen::MatrixXd() : Eigen::MatrixXd(w.transpose() * sys.A * w);
  const Eigen::MatrixXd b = n == 0 ? Eigen::MatrixXd(0, m) : Eigen::MatrixXd(w.transpose() * sys.B);
  const Eigen::MatrixXd c = n == 0 ? Eigen::MatrixXd(p, 0) : Eigen::MatrixXd(sys.C * w);
  // a is block upper triangular up to rounding (the first ns columns of w are invariant);
  // T = [I X; 0 I] then removes the coupling block.
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(ns, nu);
  if (ns > 0 && nu > 0)
    x = decoupling_solution(a.topLeftCorner(ns, ns), a.bottomRightCorner(nu, nu), a.topRightCorner(ns, nu));
  StableSplit out;
  out.stable = {a.topLeftCorner(ns, ns), b.topRows(ns) - x * b.bottomRows(nu), c.leftCols(ns), sys.D};
  out.unstable = {a.bottomRightCorner(nu, nu), b.bottomRows(nu), c.leftCols(ns) * x + c.rightCols(nu),
                  Eigen::MatrixXd::Zero(p, m)};
  return out;
}

BalancedTruncation balanced_truncation_stable_part(const StableSplit& split, Eigen::Index order) {
  const Eigen::Index nu = split.unstable.states(), n = split.stable.states() + nu;
  if (order < nu || order > n)
    throw std::invalid_argument("balanced_truncation_stable_part: order must lie between the " + std::to_string(nu) +
                                " unstable states and the system's " + std::to_string(n));
  BalancedTruncation out = balanced_truncation(split.stable, order - nu);
  out.reduced = parallel(out.reduced, split.unstable);
  out.unstable_states = nu;
  return out;
}

BalancedTruncation balanced_truncation_stable_part(const StateSpace& sys, Eigen::Index order, double alpha) {
  return balanced_truncation_stable_part(stable_split(sys, alpha), order);
}

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
