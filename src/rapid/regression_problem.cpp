// RegressionProblem: the factored least-squares problem, its export to normal equations, the
// stable re-factorization of imported normal equations, and merging.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "regression_qr.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/rapid/regression.hpp"

namespace servotwin::rapid {

namespace {

using detail::kAugmentedColumns;
using Vector9 = Eigen::Matrix<double, kAugmentedColumns, 1>;

core::InputError field_error(const char* field, const std::string& message) {
  return core::InputError(core::at_field(field), message);
}

bool all_finite(const Matrix9& m) noexcept { return m.allFinite(); }

void validate_ts(double ts, const char* field) {
  if (!std::isfinite(ts) || ts <= 0.0) {
    throw field_error(field, "sample period must be a finite positive number of seconds, got " + std::to_string(ts));
  }
}

/// Exact power-of-two column scales that bring the largest entry of each column of both factors
/// into [1, 2): the Householder update then never meets overflow or underflow, whatever the units.
Vector9 column_scales(const Matrix9& a, const Matrix9& b) {
  Vector9 s;
  for (int j = 0; j < kAugmentedColumns; ++j) {
    s(j) = detail::power_of_two_scale(std::max(a.col(j).cwiseAbs().maxCoeff(), b.col(j).cwiseAbs().maxCoeff()));
  }
  return s;
}

/// The triangular factor of [a; b] (both 9 x 9), computed in scaled columns.
Matrix9 stacked_factor(const Matrix9& a, const Matrix9& b) {
  const Vector9 s = column_scales(a, b);
  Matrix9 u = a * s.asDiagonal();
  detail::make_diagonal_nonnegative(u);
  Matrix9 block = b * s.asDiagonal();  // column-major, leading dimension 9
  detail::triangular_update(u, block.data(), kAugmentedColumns, kAugmentedColumns);
  return u * s.cwiseInverse().asDiagonal();
}

/// Result of a pivoted Cholesky factorization of a scaled Gram matrix.
struct PivotedCholesky {
  Matrix9 l = Matrix9::Zero();  ///< lower trapezoidal, columns 0..rank-1 used
  std::array<int, kAugmentedColumns> perm{};
  int rank = 0;
  bool indefinite = false;
};

/// Pivoted (diagonal pivoting) Cholesky of the leading `n` x `n` block of a symmetric matrix with
/// unit or zero diagonal. Stops when the largest remaining pivot is at rounding level; then the
/// remaining Schur complement must be zero up to rounding, otherwise the matrix is indefinite.
PivotedCholesky pivoted_cholesky(Matrix9 a, int n) {
  // The Schur complement of a positive semidefinite matrix with unit diagonal loses accuracy at
  // about n * eps per step; a remaining pivot below `negligible` is rank deficiency, an entry
  // of the remainder beyond `indefinite_level` cannot be rounding.
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double negligible = 64.0 * kAugmentedColumns * eps;
  const double indefinite_level = 1e-9;
  PivotedCholesky out;
  for (int i = 0; i < n; ++i) out.perm[static_cast<std::size_t>(i)] = i;
  int k = 0;
  for (; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i) {
      if (a(i, i) > a(p, p)) p = i;
    }
    if (a(p, p) <= negligible) break;
    if (p != k) {
      a.row(k).swap(a.row(p));
      a.col(k).swap(a.col(p));
      out.l.row(k).swap(out.l.row(p));
      std::swap(out.perm[static_cast<std::size_t>(k)], out.perm[static_cast<std::size_t>(p)]);
    }
    const double d = std::sqrt(a(k, k));
    out.l(k, k) = d;
    for (int i = k + 1; i < n; ++i) out.l(i, k) = a(i, k) / d;
    for (int j = k + 1; j < n; ++j) {
      for (int i = j; i < n; ++i) {
        a(i, j) -= out.l(i, k) * out.l(j, k);
        a(j, i) = a(i, j);
      }
    }
  }
  out.rank = k;
  for (int j = k; j < n; ++j) {
    for (int i = k; i < n; ++i) {
      if (std::abs(a(i, j)) > indefinite_level || (i == j && a(i, i) < -indefinite_level)) out.indefinite = true;
    }
  }
  return out;
}

/// Gram matrix [P R; R^T Gamma] of exported statistics.
Matrix9 augmented_gram(const NormalEquations& ne) {
  Matrix9 g;
  g.topLeftCorner<kParameterCount, kParameterCount>() = ne.P;
  g.topRightCorner<kParameterCount, 1>() = ne.R;
  g.bottomLeftCorner<1, kParameterCount>() = ne.R.transpose();
  g(kParameterCount, kParameterCount) = ne.gamma;
  return g;
}

void validate_statistics(const NormalEquations& ne) {
  if (ne.n == 0) throw field_error("N", "sample count must be at least 1");
  validate_ts(ne.ts, "Ts");
  for (int i = 0; i < kParameterCount; ++i) {
    for (int j = 0; j < kParameterCount; ++j) {
      if (!std::isfinite(ne.P(i, j))) {
        throw field_error("P", "entry (" + std::to_string(i) + ", " + std::to_string(j) + ") is not finite");
      }
    }
    if (!std::isfinite(ne.R(i))) throw field_error("R", "entry " + std::to_string(i) + " is not finite");
  }
  if (!std::isfinite(ne.gamma)) throw field_error("Gamma", "is not finite");
  if (ne.gamma < 0.0) throw field_error("Gamma", "y^T y must not be negative, got " + std::to_string(ne.gamma));
  for (int i = 0; i < kParameterCount; ++i) {
    if (ne.P(i, i) < 0.0) {
      throw field_error("P", "diagonal entry (" + std::to_string(i) + ", " + std::to_string(i) +
                                 ") is negative; Phi^T Phi has a non-negative diagonal");
    }
  }
  // Symmetry up to the rounding of a text round trip, relative to the geometric mean of the
  // diagonal (the natural scale of an entry of a Gram matrix).
  constexpr double symmetry_tolerance = 1e-10;
  for (int i = 0; i < kParameterCount; ++i) {
    for (int j = i + 1; j < kParameterCount; ++j) {
      const double scale = std::sqrt(ne.P(i, i) * ne.P(j, j));
      if (std::abs(ne.P(i, j) - ne.P(j, i)) > symmetry_tolerance * std::max(scale, std::abs(ne.P(i, j)))) {
        throw field_error("P", "is not symmetric: entries (" + std::to_string(i) + ", " + std::to_string(j) + ") = " +
                                   std::to_string(ne.P(i, j)) + " and (" + std::to_string(j) + ", " +
                                   std::to_string(i) + ") = " + std::to_string(ne.P(j, i)));
      }
    }
  }
}

}  // namespace

RegressionProblem::RegressionProblem(const Matrix9& factor, std::uint64_t samples, double ts)
    : u_(factor), n_(samples), ts_(ts) {
  validate_ts(ts, "Ts");
  if (!all_finite(factor)) throw field_error("factor", "the triangular factor has non-finite entries");
  for (int j = 0; j < kAugmentedColumns; ++j) {
    for (int i = j + 1; i < kAugmentedColumns; ++i) {
      if (factor(i, j) != 0.0) {
        throw field_error("factor", "must be upper triangular; entry (" + std::to_string(i) + ", " +
                                        std::to_string(j) + ") is " + std::to_string(factor(i, j)));
      }
    }
  }
  if (samples == 0 && !factor.isZero(0.0)) {
    throw field_error("N", "a problem without samples must have a zero factor");
  }
  detail::make_diagonal_nonnegative(u_);
}

namespace {

/// R^T P^+ R of the scaled augmented matrix c (unit diagonal: Gamma's entry is 1), the least
/// Gamma (relative to the given one) for which [P R; R^T Gamma] is semidefinite; empty when R lies
/// outside the range of P beyond rounding (then no Gamma helps: the objective is unbounded below).
std::optional<double> least_relative_gamma(const Matrix9& c) {
  const Eigen::Matrix<double, kParameterCount, kParameterCount> p = c.topLeftCorner<kParameterCount, kParameterCount>();
  const Vector8 r = c.topRightCorner<kParameterCount, 1>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kParameterCount, kParameterCount>> eigen(p);
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  const double tolerance = 1e-10 * std::max(largest, 1.0);
  double q = 0.0;
  Vector8 outside = r;
  for (int i = 0; i < kParameterCount; ++i) {
    const double lambda = eigen.eigenvalues()(i);
    if (lambda <= tolerance) continue;
    const double projection = eigen.eigenvectors().col(i).dot(r);
    q += projection * projection / lambda;
    outside -= projection * eigen.eigenvectors().col(i);
  }
  if (outside.norm() > 1e-8 * std::max(r.norm(), 1.0)) return std::nullopt;
  return q;
}

}  // namespace

RegressionProblem RegressionProblem::from_normal_equations(const NormalEquations& ne, std::vector<std::string>* warnings) {
  validate_statistics(ne);
  const Matrix9 g = augmented_gram(ne);
  // Symmetric scaling to unit diagonal: the factorization then sees the correlation structure
  // only, so its pivot tolerance means the same thing in any units.
  Vector9 s;
  for (int i = 0; i < kAugmentedColumns; ++i) s(i) = g(i, i) > 0.0 ? std::sqrt(g(i, i)) : 0.0;
  const Vector9 s_inv = s.unaryExpr([](double v) { return v > 0.0 ? 1.0 / v : 0.0; });
  Matrix9 c = s_inv.asDiagonal() * g * s_inv.asDiagonal();
  c = 0.5 * (c + c.transpose()).eval();
  for (int i = 0; i < kAugmentedColumns; ++i) {
    if (s(i) == 0.0) {
      // An all-zero column (e.g. a direction that never occurred) must have zero correlations.
      for (int j = 0; j < kAugmentedColumns; ++j) {
        if (g(i, j) != 0.0 || g(j, i) != 0.0) {
          throw field_error(i < kParameterCount ? (j < kParameterCount ? "P" : "R") : "R",
                            "is indefinite: diagonal entry " + std::to_string(i) +
                                " is zero but its row has nonzero entries");
        }
      }
    }
  }
  if (pivoted_cholesky(c, kParameterCount).indefinite) {
    throw field_error("P", "is indefinite beyond rounding: not the Gram matrix Phi^T Phi of any regressor matrix");
  }
  const PivotedCholesky chol = pivoted_cholesky(c, kAugmentedColumns);
  if (chol.indefinite) {
    // Issue 27 §3.17: a Gamma printed with two decimals falls below R^T P^+ R; the minimizer does
    // not depend on Gamma, so such statistics are solved with Gamma raised to the least consistent
    // value (and a warning), and only an R outside P's range is refused.
    const std::optional<double> least = least_relative_gamma(c);
    if (warnings != nullptr && least && *least >= 1.0) {
      NormalEquations raised = ne;
      raised.gamma = ne.gamma * *least * (1.0 + 1e-8);
      RegressionProblem problem = from_normal_equations(raised, nullptr);
      warnings->push_back("objective shifted: Gamma = " + std::to_string(ne.gamma) + " is below R^T P^+ R = " +
                          std::to_string(ne.gamma * *least) + ", inconsistent with P and R" +
                          (*least < 1.01 ? " (probably rounded)" : " by more than rounding explains: check the statistics") +
                          "; solved with the least consistent Gamma, which leaves the minimizer unchanged and the "
                          "objective's level unknown");
      return problem;
    }
    throw field_error(least ? "Gamma" : "R",
                      least ? "[P R; R^T Gamma] is indefinite beyond rounding (Gamma < R^T P^+ R): not the statistics "
                              "of any data"
                            : "lies outside the range of P beyond rounding: the objective has no minimum; not the "
                              "statistics of any data");
  }
  // C = Pi L L^T Pi^T, so G = M^T M with M = L^T Pi^T S; M is re-triangularized by Householder
  // reflections into the canonical upper-triangular factor in the original column order.
  Matrix9 m = Matrix9::Zero();
  for (int r = 0; r < chol.rank; ++r) {
    for (int k = r; k < kAugmentedColumns; ++k) {
      const int col = chol.perm[static_cast<std::size_t>(k)];
      m(r, col) = chol.l(k, r) * s(col);
    }
  }
  Matrix9 u = Matrix9::Zero();
  const Vector9 scale = column_scales(u, m);
  Matrix9 block = m * scale.asDiagonal();
  detail::triangular_update(u, block.data(), kAugmentedColumns, kAugmentedColumns);
  return RegressionProblem(Matrix9(u * scale.cwiseInverse().asDiagonal()), ne.n, ne.ts);
}

NormalEquations RegressionProblem::normal_equations() const {
  // Upper triangle by explicit dot products, mirrored: the exported matrix is exactly symmetric.
  Matrix9 g;
  for (int i = 0; i < kAugmentedColumns; ++i) {
    for (int j = i; j < kAugmentedColumns; ++j) {
      const int top = std::min(i, j) + 1;
      g(i, j) = u_.col(i).head(top).dot(u_.col(j).head(top));
      g(j, i) = g(i, j);
    }
  }
  NormalEquations ne;
  ne.P = g.topLeftCorner<kParameterCount, kParameterCount>();
  ne.R = g.topRightCorner<kParameterCount, 1>();
  ne.gamma = g(kParameterCount, kParameterCount);
  ne.n = n_;
  ne.ts = ts_;
  return ne;
}

double RegressionProblem::objective(const Vector8& theta) const {
  // y - Phi theta = [Phi y] v with v = [-theta; 1], and ||[Phi y] v|| = ||U v||: the residual is
  // formed from the factor, so no cancellation between Gamma and the quadratic form occurs.
  Vector9 v;
  v.head<kParameterCount>() = -theta;
  v(kParameterCount) = 1.0;
  const Vector9 r = u_.triangularView<Eigen::Upper>() * v;
  return 0.5 * r.squaredNorm();
}

RegressionProblem& RegressionProblem::merge(const RegressionProblem& other) {
  if (other.empty()) return *this;
  if (empty()) {
    *this = other;
    return *this;
  }
  if (std::abs(ts_ - other.ts_) > 1e-9 * std::max(ts_, other.ts_)) {
    throw field_error("Ts", "cannot merge problems with different sample periods (" + std::to_string(ts_) + " s and " +
                                std::to_string(other.ts_) + " s); resample one capture first");
  }
  u_ = stacked_factor(u_, other.u_);
  n_ += other.n_;
  return *this;
}

}  // namespace servotwin::rapid
