#include "velocity_sign_bound.hpp"

#include <algorithm>
#include <numbers>

namespace servotwin::rapid::detail {

namespace {

// Beyond this the rows of the inverse Vandermonde matrix amplify rounding so much that the
// margin would refuse every sample: the simulation keeps the event search instead.
constexpr double kMaxRowScale = 1e8;
constexpr double kMaxGrowth = 700.0;  // exp(700) is near the largest double

// Lagrange row of pole i: coefficients of (s - lj)(s - lk) / ((li - lj)(li - lk)) on (1, s, s^2).
std::array<std::complex<double>, 3> lagrange_row(std::complex<double> li, std::complex<double> lj,
                                                 std::complex<double> lk) {
  const std::complex<double> d = (li - lj) * (li - lk);
  return {lj * lk / d, -(lj + lk) / d, 1.0 / d};
}

double largest_entry(const std::array<std::complex<double>, 3>& row) {
  return std::max({std::abs(row[0]), std::abs(row[1]), std::abs(row[2])});
}

// Newton steps on the monic cubic while they reduce |p|: polishes a closed-form root to the
// rounding level of p's evaluation (the closed forms lose digits to cancellation).
template <typename T>
T polished(T root, double a, double b, double c) {
  auto value = [&](T s) { return ((s + a) * s + b) * s + c; };
  T p = value(root);
  for (int it = 0; it < 8; ++it) {
    const T slope = (3.0 * root + 2.0 * a) * root + b;
    if (slope == T{}) break;
    const T next = root - p / slope;
    const T q = value(next);
    if (!(std::abs(q) < std::abs(p))) break;
    root = next;
    p = q;
  }
  return root;
}

// Roots of s^3 + a s^2 + b s + c without allocation (the simulation builds this once per call and
// must not allocate): the trigonometric form for three real roots, otherwise Cardano's real root
// (written without cancellation, Numerical Recipes 3rd ed. section 5.6) and the quadratic left by
// deflating it; every root polished on the cubic itself.
std::array<std::complex<double>, 3> cubic_roots(double a, double b, double c) {
  const double q = (a * a - 3.0 * b) / 9.0;
  const double r = (2.0 * a * a * a - 9.0 * a * b + 27.0 * c) / 54.0;
  if (r * r < q * q * q) {
    const double theta = std::acos(std::clamp(r / std::sqrt(q * q * q), -1.0, 1.0));
    const double m = -2.0 * std::sqrt(q);
    std::array<std::complex<double>, 3> out;
    for (int k = 0; k < 3; ++k)
      out[static_cast<std::size_t>(k)] = polished(m * std::cos((theta + 2.0 * std::numbers::pi * k) / 3.0) - a / 3.0, a, b, c);
    return out;
  }
  const double big = -std::copysign(std::cbrt(std::abs(r) + std::sqrt(r * r - q * q * q)), r);
  const double real = polished((big == 0.0 ? 0.0 : big + q / big) - a / 3.0, a, b, c);
  // s^3 + a s^2 + b s + c = (s - real)(s^2 + p1 s + p0)
  const double p1 = a + real, p0 = b + real * p1;
  const double disc = p1 * p1 - 4.0 * p0;
  if (disc >= 0.0) {
    const double t = -0.5 * (p1 + std::copysign(std::sqrt(disc), p1));
    const double other = t != 0.0 ? p0 / t : 0.0;
    return {real, polished(t, a, b, c), polished(other, a, b, c)};
  }
  const std::complex<double> upper = polished(std::complex<double>(-0.5 * p1, 0.5 * std::sqrt(-disc)), a, b, c);
  return {real, upper, std::conj(upper)};
}

}  // namespace

VelocitySignBound::VelocitySignBound(double a1, double a2, double a3, double ts) {
  if (!(std::isfinite(a1) && std::isfinite(a2) && std::isfinite(a3) && std::isfinite(ts) && ts > 0.0)) return;
  // The poles in units of 1/ts: the roots of the cubic in l ts.
  const std::array<std::complex<double>, 3> poles = cubic_roots(a1 * ts, a2 * ts * ts, a3 * ts * ts * ts);
  double row_scale = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::complex<double> li = poles[i], lj = poles[(i + 1) % 3], lk = poles[(i + 2) % 3];
    if (!std::isfinite(li.real()) || !std::isfinite(li.imag()) || li.real() > kMaxGrowth) return;
    if (li == lj || li == lk) return;  // a multiple pole: no modal basis
    const std::array<std::complex<double>, 3> row = lagrange_row(li, lj, lk);
    const double envelope = std::max(1.0, std::exp(li.real()));
    if (li.imag() == 0.0) {
      const auto n = static_cast<std::size_t>(real_count_++);
      real_row_[n] = {row[0].real(), row[1].real(), row[2].real()};
      real_end_[n] = std::exp(li.real());
      real_curvature_[n] = li.real() * li.real() * envelope / 8.0;
      for (std::size_t j = 0; j + 1 < kGrid; ++j)
        real_grid_[n][j] = std::exp(li.real() * static_cast<double>(j + 1) / static_cast<double>(kGrid));
      row_scale += envelope * largest_entry(row);
    } else if (li.imag() > 0.0) {
      has_pair_ = true;
      for (std::size_t k = 0; k < 3; ++k) {
        pair_re_[k] = row[k].real();
        pair_im_[k] = row[k].imag();
      }
      pair_end_ = std::exp(li);
      for (std::size_t j = 0; j + 1 < kGrid; ++j) {
        const std::complex<double> e = std::exp(li * (static_cast<double>(j + 1) / static_cast<double>(kGrid)));
        pair_grid_re_[j] = e.real();
        pair_grid_im_[j] = e.imag();
      }
      pair_envelope_ = envelope;
      pair_curvature_ = std::norm(li) * envelope / 8.0;
      row_scale += 2.0 * envelope * largest_entry(row);  // the pair counts twice
    }
  }
  if (!std::isfinite(row_scale) || row_scale > kMaxRowScale) return;
  row_scale_ = row_scale;
  usable_ = true;
}

}  // namespace servotwin::rapid::detail
