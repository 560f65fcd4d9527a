// Distance from the origin to the convex hull of a few points in R^3, by Wolfe's minimum-norm-point
// algorithm (Math. Programming 11, 1976), with a certificate: for the point x found,
//   dist(0, conv{z_i}) >= min_i <x, z_i> / ||x||,
// because the whole hull lies in that half-space. The bound holds whatever the iteration reached;
// convergence only makes it tight. The exact solver's box bounds rest on it.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "servotwin/rapid/solver_detail.hpp"

namespace servotwin::rapid::detail {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// Coefficients (summing to 1) of the point of the affine hull of z[s[0..k)] nearest to the origin;
/// dependent points get coefficient 0.
std::array<double, 4> affine_minimum(const Eigen::Vector3d* z, const std::array<int, 4>& s, int k) {
  std::array<double, 4> alpha{1.0, 0.0, 0.0, 0.0};
  if (k == 1) return alpha;
  const Eigen::Vector3d& z0 = z[s[0]];
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3> d(3, k - 1);
  for (int i = 1; i < k; ++i) d.col(i - 1) = z[s[static_cast<std::size_t>(i)]] - z0;
  Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3>> qr(d);
  qr.setThreshold(1e-12);
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> beta = qr.solve(-z0);
  double sum = 0.0;
  for (int i = 1; i < k; ++i) {
    alpha[static_cast<std::size_t>(i)] = beta(i - 1);
    sum += beta(i - 1);
  }
  alpha[0] = 1.0 - sum;
  return alpha;
}

}  // namespace

PolytopeDistance polytope_distance(const Eigen::Vector3d* z, int count) {
  PolytopeDistance out;
  if (count <= 0) return out;
  double scale = 0.0;
  int first = 0;
  for (int i = 0; i < count; ++i) {
    scale = std::max(scale, z[i].squaredNorm());
    if (z[i].squaredNorm() < z[first].squaredNorm()) first = i;
  }
  std::array<int, 4> s{first, 0, 0, 0};
  std::array<double, 4> lambda{1.0, 0.0, 0.0, 0.0};
  int k = 1;
  Eigen::Vector3d x = z[first];
  for (int major = 0; major < 64 && k <= 4; ++major) {
    int j = 0;
    for (int i = 1; i < count; ++i) {
      if (x.dot(z[i]) < x.dot(z[j])) j = i;
    }
    // Stop when no point lies beyond the plane through x by more than the dot products' rounding.
    const double xx = x.squaredNorm();
    if (xx - x.dot(z[j]) <= 8.0 * kEps * x.norm() * std::sqrt(scale)) break;
    if (k == 4 || std::find(s.begin(), s.begin() + k, j) != s.begin() + k) break;  // rounding stall
    s[static_cast<std::size_t>(k)] = j;
    lambda[static_cast<std::size_t>(k)] = 0.0;
    ++k;
    for (int minor = 0; minor < 16; ++minor) {
      const std::array<double, 4> alpha = affine_minimum(z, s, k);
      bool interior = true;
      for (int i = 0; i < k; ++i) interior = interior && alpha[static_cast<std::size_t>(i)] > 0.0;
      if (interior) {
        lambda = alpha;
        break;
      }
      // Move from lambda towards alpha until a weight vanishes, drop the vanished points.
      double theta = 1.0;
      for (int i = 0; i < k; ++i) {
        const double l = lambda[static_cast<std::size_t>(i)], a = alpha[static_cast<std::size_t>(i)];
        if (a <= 0.0 && l > a) theta = std::min(theta, l / (l - a));
      }
      int kept = 0;
      for (int i = 0; i < k; ++i) {
        const auto ui = static_cast<std::size_t>(i);
        const double l = (1.0 - theta) * lambda[ui] + theta * alpha[ui];
        if (l > 1e-14) {
          s[static_cast<std::size_t>(kept)] = s[ui];
          lambda[static_cast<std::size_t>(kept)] = l;
          ++kept;
        }
      }
      if (kept == 0) {
        kept = 1;
        lambda[0] = 1.0;
      }
      k = kept;
      double total = 0.0;
      for (int i = 0; i < k; ++i) total += lambda[static_cast<std::size_t>(i)];
      for (int i = 0; i < k; ++i) lambda[static_cast<std::size_t>(i)] /= total;
    }
    x.setZero();
    for (int i = 0; i < k; ++i) x += lambda[static_cast<std::size_t>(i)] * z[s[static_cast<std::size_t>(i)]];
  }
  out.point = x;
  const double norm = x.norm();
  if (!(norm > 0.0)) return out;
  double support = std::numeric_limits<double>::infinity();
  double largest = 0.0;
  for (int i = 0; i < count; ++i) {
    support = std::min(support, x.dot(z[i]));
    largest = std::max(largest, z[i].norm());
  }
  // Rounding of the dot products and of the division: a few eps of ||x|| ||z_i||.
  const double bound = support / norm - 16.0 * kEps * largest;
  out.lower_bound = std::max(bound, 0.0);
  return out;
}

}  // namespace servotwin::rapid::detail
