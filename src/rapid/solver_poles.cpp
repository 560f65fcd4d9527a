// The map between the search variables (p, wn, zeta) and theta1 = (alpha_i, alpha_1, alpha_2)
// (Eq. 3.14), its derivatives in the solvers' coordinates (ln p, ln wn, zeta), and its inverse.
//
// With s = p / wn and k = 1 + 2 zeta s (so a2 = wn^2 k > 0):
//   alpha_2 = 1 / (wn^2 k),  alpha_i = p / k,  alpha_1 = (s + 2 zeta) / (wn k).

#include <algorithm>
#include <cmath>
#include <complex>

#include "servotwin/core/polynomial.hpp"
#include "servotwin/rapid/solver.hpp"
#include "servotwin/rapid/solver_detail.hpp"

namespace servotwin::rapid {

Eigen::Vector3d theta1_from_poles(double p, double wn, double zeta) noexcept {
  const double a1 = p + 2.0 * zeta * wn;
  const double a2 = wn * (wn + 2.0 * p * zeta);
  return {p * wn / (wn + 2.0 * p * zeta), a1 / a2, 1.0 / a2};
}

std::vector<PoleFactorization> pole_factorizations(const Eigen::Vector3d& theta1) {
  std::vector<PoleFactorization> out;
  if (!theta1.allFinite() || theta1(2) == 0.0) return out;
  // alpha_2 s^3 + alpha_1 s^2 + s + alpha_i has the roots of the characteristic polynomial.
  const core::Polynomial poly{theta1(2), theta1(1), 1.0, theta1(0)};
  const std::vector<std::complex<double>> roots = poly.roots();
  if (roots.size() != 3) return out;
  std::vector<double> real;
  std::complex<double> pair{0.0, 0.0};
  for (const auto& r : roots) {
    if (r.imag() == 0.0) {
      real.push_back(r.real());
    } else if (r.imag() > 0.0) {
      pair = r;
    }
  }
  if (real.size() == 1) {
    const double wn = std::abs(pair);
    out.push_back({-real[0], wn, -pair.real() / wn});
    return out;
  }
  for (std::size_t k = 0; k < real.size(); ++k) {
    const double ra = real[(k + 1) % 3], rb = real[(k + 2) % 3];
    const double product = ra * rb;
    if (!(product > 0.0)) continue;
    const double wn = std::sqrt(product);
    const PoleFactorization f{-real[k], wn, -(ra + rb) / (2.0 * wn)};
    const bool duplicate = std::any_of(out.begin(), out.end(), [&](const PoleFactorization& g) {
      return g.p == f.p && g.wn == f.wn && g.zeta == f.zeta;
    });
    if (!duplicate) out.push_back(f);
  }
  return out;
}

namespace detail {

Eigen::Matrix3d theta1_log_jacobian(double p, double wn, double zeta) noexcept {
  const double s = p / wn;
  const double k = 1.0 + 2.0 * zeta * s;
  const double ik2 = 1.0 / (k * k);
  const double iw = 1.0 / wn;
  Eigen::Matrix3d j;
  // rows alpha_i, alpha_1, alpha_2; columns d/d ln p, d/d ln wn, d/d zeta
  j(0, 0) = p * ik2;
  j(0, 1) = 2.0 * zeta * s * s * wn * ik2;
  j(0, 2) = -2.0 * p * s * ik2;
  j(1, 0) = s * (1.0 - 4.0 * zeta * zeta) * iw * ik2;
  j(1, 1) = -2.0 * (zeta + s + s * s * zeta) * iw * ik2;
  j(1, 2) = 2.0 * (1.0 - s * s) * iw * ik2;
  j(2, 0) = -2.0 * zeta * s * iw * iw * ik2;
  j(2, 1) = -(2.0 + 2.0 * zeta * s) * iw * iw * ik2;
  j(2, 2) = -2.0 * s * iw * iw * ik2;
  return j;
}

}  // namespace detail

}  // namespace servotwin::rapid
