#include "servotwin/frf/observer_gains.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/core/riccati.hpp"

namespace servotwin::frf {

namespace {

using Complex = std::complex<double>;

void require_in(double value, double low, double high, const char* field, const char* expected) {
  if (!std::isfinite(value) || value <= low || value > high)
    throw core::InputError(core::at_field(field), std::string("expected ") + expected + ", got " + std::to_string(value));
}

/// Desired characteristic polynomial prod(s - s_m) of the Butterworth pattern, evaluated at s.
Complex butterworth_polynomial(double alpha0, Complex s) {
  Complex p = 1.0;
  for (int m = 1; m <= kObserverStates; ++m) {
    const double angle = (2.0 * m + 10.0) * std::numbers::pi / 22.0;
    p *= s - std::polar(alpha0, angle);
  }
  return p;
}

/// prod_{l=1..5, l != skip} (s^2 + l^2).
Complex oscillator_product(Complex s, int skip) {
  Complex p = 1.0;
  for (int l = 1; l <= kHarmonicCount; ++l)
    if (l != skip) p *= s * s + static_cast<double>(l * l);
  return p;
}

}  // namespace

ObserverMatrix internal_model(double omega) {
  ObserverMatrix a = ObserverMatrix::Zero();
  for (int i = 1; i <= kHarmonicCount; ++i) {
    a(2 * i - 2, 2 * i - 1) = i * omega;
    a(2 * i - 1, 2 * i - 2) = -i * omega;
  }
  return a;
}

ObserverRow output_row() {
  ObserverRow c = ObserverRow::Zero();
  for (int i = 0; i < kObserverStates; i += 2) c(i) = 1.0;
  return c;
}

ObserverVector default_kalman_weights() {
  ObserverVector w;
  w << 0.4, 0.4, 0.6, 0.6, 0.8, 0.8, 0.9, 0.9, 1.0, 1.0, 0.6;
  return w;
}

ObserverVector butterworth_gains(double alpha0) {
  require_in(alpha0, 0.0, 50.0, "alpha0", "a relative observer bandwidth in (0, 50] (recommended 2.8)");
  ObserverVector k;
  // a(s) = s prod(s^2 + i^2); at s = j i every term of p(s) - a(s) but harmonic i's vanishes.
  for (int i = 1; i <= kHarmonicCount; ++i) {
    const Complex s(0.0, i);
    const Complex cofactor = s * oscillator_product(s, i);  // a(s) / (s^2 + i^2)
    const Complex q = butterworth_polynomial(alpha0, s) / cofactor;  // i k_{2i} + j i k_{2i-1}
    k(2 * i - 2) = q.imag() / i;
    k(2 * i - 1) = q.real() / i;
  }
  k(kDcState) = butterworth_polynomial(alpha0, 0.0).real() / oscillator_product(0.0, 0).real();
  return k;
}

ObserverVector kalman_gains(double v, const ObserverVector& weights) {
  require_in(v, 0.0, 1e12, "v", "a measurement-noise intensity V > 0 (e.g. 0.02)");
  for (int i = 0; i < kObserverStates; ++i)
    if (!std::isfinite(weights(i)) || weights(i) <= 0.0)
      throw core::InputError(core::at_field("weights[" + std::to_string(i) + "]"),
                             "expected a finite process-noise weight > 0, got " + std::to_string(weights(i)));
  const Eigen::MatrixXd a = internal_model(1.0);
  const Eigen::MatrixXd c = output_row();
  const Eigen::MatrixXd w = weights.asDiagonal();
  const Eigen::MatrixXd vm = Eigen::MatrixXd::Constant(1, 1, v);
  const Eigen::MatrixXd y = core::solve_care_filter(a, c, w, vm);
  return (y * c.transpose() / v);
}

ObserverVector design_gains(const ObserverDesign& design) {
  return design.design == GainDesign::kKalman ? kalman_gains(design.v) : butterworth_gains(design.alpha0);
}

std::complex<double> observer_response(const ObserverVector& k1, int channel, std::complex<double> s) {
  const Eigen::Matrix<Complex, kObserverStates, kObserverStates> m =
      s * Eigen::Matrix<Complex, kObserverStates, kObserverStates>::Identity() -
      (internal_model(1.0) - k1 * output_row()).cast<Complex>();
  const Eigen::Matrix<Complex, kObserverStates, 1> x = m.partialPivLu().solve(k1.cast<Complex>());
  if (channel < 0) return (output_row().cast<Complex>() * x)(0);
  if (channel == 0) return x(kDcState);
  return x(2 * std::clamp(channel, 1, kHarmonicCount) - 2);
}

double observer_peak_gain(const ObserverVector& k1, int channel, double w_min, double w_max, int points) {
  const double log_min = std::log(w_min), log_max = std::log(w_max);
  const auto gain_at = [&](double log_w) { return std::abs(observer_response(k1, channel, {0.0, std::exp(log_w)})); };
  const double step = (log_max - log_min) / std::max(points - 1, 1);
  int best = 0;
  double best_gain = -1.0;
  for (int i = 0; i < points; ++i) {
    const double g = gain_at(log_min + step * i);
    if (g > best_gain) {
      best_gain = g;
      best = i;
    }
  }
  // Golden-section search for the maximum within one grid step either side.
  double lo = log_min + step * std::max(best - 1, 0), hi = log_min + step * std::min(best + 1, points - 1);
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
  double ga = gain_at(a), gb = gain_at(b);
  for (int it = 0; it < 60; ++it) {
    if (ga > gb) {
      hi = b; b = a; gb = ga; a = hi - ratio * (hi - lo); ga = gain_at(a);
    } else {
      lo = a; a = b; ga = gb; b = lo + ratio * (hi - lo); gb = gain_at(b);
    }
  }
  return std::max({best_gain, ga, gb});
}

}  // namespace servotwin::frf
