#include "balance.hpp"

#include <cmath>

namespace servotwin::core::detail {

Eigen::VectorXd balance(Eigen::MatrixXd& a) {
  constexpr double radix = 2.0;
  constexpr double radix2 = radix * radix;
  const Eigen::Index n = a.rows();
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
  bool converged = false;
  // Each accepted scaling reduces the total off-diagonal norm by at least 5 %, so the sweeps end;
  // the cap only guards against non-finite input.
  for (int sweep = 0; sweep < 200 && !converged; ++sweep) {
    converged = true;
    for (Eigen::Index i = 0; i < n; ++i) {
      double col = 0.0;
      double row = 0.0;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (j == i) continue;
        col += std::abs(a(j, i));
        row += std::abs(a(i, j));
      }
      if (col == 0.0 || row == 0.0 || !std::isfinite(col + row)) continue;
      const double total = col + row;
      double f = 1.0;
      double g = row / radix;
      while (col < g) {
        f *= radix;
        col *= radix2;
      }
      g = row * radix;
      while (col > g) {
        f /= radix;
        col /= radix2;
      }
      if ((col + row) / f < 0.95 * total) {
        converged = false;
        a.row(i) /= f;
        a.col(i) *= f;
        scale(i) *= f;
      }
    }
  }
  return scale;
}

StateSpace balanced(const StateSpace& sys) {
  StateSpace b = sys;
  const Eigen::VectorXd t = balance(b.A);
  b.B = t.cwiseInverse().asDiagonal() * sys.B;
  b.C = sys.C * t.asDiagonal();
  return b;
}

}  // namespace servotwin::core::detail
