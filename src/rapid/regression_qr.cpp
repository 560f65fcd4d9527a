#include "regression_qr.hpp"

#include <cmath>

namespace servotwin::rapid::detail {

namespace {

using ColumnMap = Eigen::Map<Eigen::VectorXd>;

}  // namespace

void triangular_update(Matrix9& u, double* block, std::size_t ld, std::size_t rows) noexcept {
  if (rows == 0) return;
  const auto n = static_cast<Eigen::Index>(rows);
  for (int j = 0; j < kAugmentedColumns; ++j) {
    ColumnMap bj(block + static_cast<std::size_t>(j) * ld, n);
    const double below = bj.squaredNorm();
    // A column that is already zero below the diagonal needs no reflection.
    if (below == 0.0) continue;
    const double ujj = u(j, j);
    const double norm = std::sqrt(ujj * ujj + below);
    // Reflect x = [ujj; bj] onto +norm e_1. v0 = ujj - norm is formed without cancellation
    // (Parlett's choice), which keeps the diagonal non-negative.
    const double v0 = ujj <= 0.0 ? ujj - norm : -below / (ujj + norm);
    const double beta = 2.0 / (v0 * v0 + below);
    for (int k = j + 1; k < kAugmentedColumns; ++k) {
      ColumnMap bk(block + static_cast<std::size_t>(k) * ld, n);
      const double f = beta * (v0 * u(j, k) + bj.dot(bk));
      u(j, k) -= f * v0;
      bk.noalias() -= f * bj;
    }
    u(j, j) = norm;
  }
}

void make_diagonal_nonnegative(Matrix9& u) noexcept {
  for (int i = 0; i < kAugmentedColumns; ++i) {
    if (u(i, i) < 0.0) u.row(i) = -u.row(i);
  }
}

double power_of_two_scale(double max_abs) noexcept {
  if (!(max_abs > 0.0) || !std::isfinite(max_abs)) return 1.0;
  return std::ldexp(1.0, -std::ilogb(max_abs));
}

}  // namespace servotwin::rapid::detail
