#pragma once
// Internal to the axis-model simulation (axis_model_simulation.cpp): a certificate that the
// model's velocity keeps its sign through a whole sample, so that the sample is one exact
// zero-order-hold step and the event search is skipped (issue 26).
//
// In a moving friction mode the inputs are held over the sample, and differentiating Eq. 3.3
// (x'' = -a2 x - a1 x' + a3 e_i + w - F, e_i' = x_r - x) twice removes every constant:
//   v''' + a1 v'' + a2 v' + a3 v = 0,
// so the velocity is a sum of the model's modes, v(t) = sum_i g_i exp(l_i t), with l_i the roots of
// s^3 + a1 s^2 + a2 s + a3 (the closed-loop poles) and g = V^-1 (v, v', v'') by the inverse
// Vandermonde matrix (Lagrange's basis). Each mode is bounded from below over the sample on its
// own: a real one is monotone (its smaller end value), a complex pair 2 Re(g e^(l t)) by the
// larger of -2|g| max|e^(l t)| and its chord's minimum less the chord error |f''|max/8. The sum of
// the bounds above zero is a certificate that holds for any speed of the model (a fast mode has
// decayed within the sample, so its envelope is small); the tangent test it complements
// (crossing_possible) assumes a velocity close to a parabola and is only used on slow models.
// When the per-mode bounds leave a sample open (a ringing pair beside a small velocity), the
// whole velocity on a grid of 8 intervals, each chord lowered by its interpolation error, decides.
// Time is scaled by the sample period (l ts, v' ts, v'' ts^2) so that the Vandermonde system is
// of order one for the models the thesis bounds.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <complex>
#include <limits>

namespace servotwin::rapid::detail {

class VelocitySignBound {
 public:
  /// From the coefficients of s^3 + a1 s^2 + a2 s + a3 and the sample period. Unusable (never
  /// certifies) when two poles nearly coincide (the inverse Vandermonde matrix loses the bound's
  /// accuracy) or a mode grows beyond exp(700) within one sample.
  VelocitySignBound(double a1, double a2, double a3, double ts);

  [[nodiscard]] bool usable() const noexcept { return usable_; }

  /// True when dir * v(t) > 0 on the whole sample for the velocity v0 with scaled derivatives
  /// d1 = v'(0) ts and d2 = v''(0) ts^2 (dir = +-1). False means "not certified", not "crosses".
  [[nodiscard]] bool keeps_sign(double dir, double v0, double d1, double d2) const noexcept {
    std::array<double, 3> g{};  // modal amplitudes of the real poles, times dir
    double lower = 0.0, curvature = 0.0;
    for (int i = 0; i < real_count_; ++i) {
      const auto n = static_cast<std::size_t>(i);
      const auto& r = real_row_[n];
      g[n] = dir * (r[0] * v0 + r[1] * d1 + r[2] * d2);
      lower += std::min(g[n], g[n] * real_end_[n]);
      curvature += std::abs(g[n]) * real_curvature_[n];
    }
    // Rounding of the modal amplitudes: each is a dot product of a row with (v0, d1, d2).
    const double margin = kMarginUnits * std::numeric_limits<double>::epsilon() * row_scale_ *
                          (std::abs(v0) + std::abs(d1) + std::abs(d2));
    // The pair in real arithmetic (std::abs of a complex calls hypot, a third of the step).
    double re = 0.0, im = 0.0;
    if (has_pair_) {
      re = dir * (pair_re_[0] * v0 + pair_re_[1] * d1 + pair_re_[2] * d2);
      im = dir * (pair_im_[0] * v0 + pair_im_[1] * d1 + pair_im_[2] * d2);
      const double f0 = 2.0 * re;
      const double f1 = 2.0 * (re * pair_end_.real() - im * pair_end_.imag());
      // The pair's bound falls as its modulus a = 2|g| grows, so an upper bound of a gives a lower
      // bound of the velocity: max + min/2 >= hypot (by at most 12 %) spares the square root, whose
      // latency was the step's largest cost; the exact modulus only for samples left open.
      const auto pair_lower = [&](double a) {
        return std::max(-a * pair_envelope_, std::min(f0, f1) - a * pair_curvature_);
      };
      const double ar = std::abs(re), ai = std::abs(im);
      if (lower + pair_lower(2.0 * (std::max(ar, ai) + 0.5 * std::min(ar, ai))) > margin) return true;
      const double a = 2.0 * std::sqrt(re * re + im * im);
      lower += pair_lower(a);
      curvature += a * pair_curvature_;
    }
    if (lower > margin) return true;
    // Second bound, for samples the per-mode bounds leave open (a ringing pair beside a small
    // velocity): the whole velocity on a grid of kGrid intervals, each chord lowered by its
    // interpolation error |v''|max h^2/8 with h = 1/kGrid (curvature holds |v''|max/8 over h = 1).
    const double chord_error = curvature / (kGrid * kGrid);
    double smallest = std::min(dir * v0, v1_of(g, re, im));
    for (std::size_t j = 0; j + 1 < kGrid && smallest > chord_error + margin; ++j) {
      double v = 0.0;
      for (int i = 0; i < real_count_; ++i) v += g[static_cast<std::size_t>(i)] * real_grid_[static_cast<std::size_t>(i)][j];
      if (has_pair_) v += 2.0 * (re * pair_grid_re_[j] - im * pair_grid_im_[j]);
      smallest = std::min(smallest, v);
    }
    return smallest > chord_error + margin;
  }

 private:
  static constexpr double kMarginUnits = 64.0;
  static constexpr std::size_t kGrid = 8;
  // dir * v at the end of the sample from the modal amplitudes (already times dir).
  [[nodiscard]] double v1_of(const std::array<double, 3>& g, double re, double im) const noexcept {
    double v = 0.0;
    for (int i = 0; i < real_count_; ++i) v += g[static_cast<std::size_t>(i)] * real_end_[static_cast<std::size_t>(i)];
    if (has_pair_) v += 2.0 * (re * pair_end_.real() - im * pair_end_.imag());
    return v;
  }

  bool usable_ = false;
  int real_count_ = 0;
  std::array<std::array<double, 3>, 3> real_row_{};  // Lagrange rows of the real poles
  std::array<double, 3> real_end_{};                 // exp(l ts)
  std::array<double, 3> real_curvature_{};           // (l ts)^2 envelope / 8
  std::array<std::array<double, kGrid - 1>, 3> real_grid_{};  // exp(l ts j/kGrid), j = 1..kGrid-1
  bool has_pair_ = false;
  std::array<double, 3> pair_re_{}, pair_im_{};     // row of the pole with Im > 0
  std::complex<double> pair_end_;                    // exp(l ts)
  std::array<double, kGrid - 1> pair_grid_re_{}, pair_grid_im_{};  // exp(l ts j/kGrid)
  double pair_envelope_ = 0.0;                       // max over the sample of |exp(l t)|
  double pair_curvature_ = 0.0;                      // |l ts|^2 envelope / 8
  double row_scale_ = 0.0;                           // sum over modes of envelope * max |row entry|
};

}  // namespace servotwin::rapid::detail
