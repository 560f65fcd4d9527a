#include "servotwin/frf/harmonic_observer.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "servotwin/core/error.hpp"

namespace servotwin::frf {
namespace {

// x = D^-1 r for the block-diagonal part D of (I - gamma A_cl): one rotation block
// [[1, -i gamma], [i gamma, 1]] per harmonic and 1 for the DC state. Returns C_o x (the sum of the
// sine states and the DC state), which the Sherman–Morrison correction needs.
inline double solve_block_diagonal(const ObserverVector& r, double gamma, ObserverVector& x) noexcept {
  double c_x = 0.0;
  for (int i = 1; i <= kHarmonicCount; ++i) {
    const double a = i * gamma;
    const double inv = 1.0 / (1.0 + a * a);
    const double s = r(2 * i - 2), c = r(2 * i - 1);
    // [[1, -a], [a, 1]]^-1 = [[1, a], [-a, 1]] / (1 + a^2)
    x(2 * i - 2) = (s + a * c) * inv;
    x(2 * i - 1) = (c - a * s) * inv;
    c_x += x(2 * i - 2);
  }
  x(kDcState) = r(kDcState);
  return c_x + x(kDcState);
}

}  // namespace

TustinRealization tustin_realization(const ObserverVector& k1, double omega, double ts) {
  const double t_prime = 2.0 * std::tan(omega * ts / 2.0) / omega;
  const ObserverMatrix a = omega * (internal_model(1.0) - k1 * output_row());
  const ObserverVector b = omega * k1;
  const ObserverMatrix identity = ObserverMatrix::Identity();
  const ObserverMatrix m2 = (identity - a * t_prime / 2.0).inverse();
  const ObserverMatrix m1 = identity + a * t_prime / 2.0;
  const ObserverVector m3 = m2 * b;
  const double root = std::sqrt(t_prime);
  return {m1 * m2, m3 * root, root * m2, m3 * t_prime / 2.0};
}

HarmonicObserver::HarmonicObserver(const ObserverVector& k1, double ts) : k1_(k1), ts_(ts) {
  if (!std::isfinite(ts) || ts <= 0.0)
    throw core::InputError(core::at_field("ts"), "expected a finite sample period > 0, got " + std::to_string(ts));
  if (!k1.allFinite()) throw core::InputError(core::at_field("k1"), "expected finite observer gains");
  reset();
}

void HarmonicObserver::reset() noexcept {
  w_.setZero();
  z_.setZero();
}

void HarmonicObserver::reset_to_dc(double dc) noexcept {
  // (I - gamma A_cl) e11 = e11 + gamma k1 (A_o e11 = 0, C_o e11 = 1), so for y = dc the state
  // w = (I - gamma A_cl) z - gamma k1 y equals dc e11 whatever gamma is.
  w_.setZero();
  w_(kDcState) = dc;
  z_.setZero();
  z_(kDcState) = dc;
}

void HarmonicObserver::set_frequency(double omega) noexcept {
  if (omega == omega_) return;
  omega_ = omega;
  gamma_ = std::tan(0.5 * omega * ts_);
  // D^-1 k1 and the Sherman–Morrison denominator 1 + gamma C_o D^-1 k1 for this gamma.
  const double c_dinv_k = solve_block_diagonal(k1_, gamma_, dinv_k_);
  sm_denominator_ = 1.0 + gamma_ * c_dinv_k;
}

void HarmonicObserver::solve_shifted(const ObserverVector& r, ObserverVector& x) const noexcept {
  const double c_dinv_r = solve_block_diagonal(r, gamma_, x);
  x -= dinv_k_ * (gamma_ * c_dinv_r / sm_denominator_);
}

void HarmonicObserver::update(double y, double omega) noexcept {
  set_frequency(omega);
  scratch_ = w_ + (gamma_ * y) * k1_;
  solve_shifted(scratch_, z_);
  w_ = 2.0 * z_ - w_;
}

double HarmonicObserver::harmonic_amplitude(int i) const noexcept {
  if (i <= 0) return std::abs(z_(kDcState));
  if (i > kHarmonicCount) return 0.0;
  return std::hypot(z_(2 * i - 2), z_(2 * i - 1));
}

double HarmonicObserver::thd() const noexcept {
  double higher = 0.0;
  for (int i = 2; i <= kHarmonicCount; ++i) {
    const double a = harmonic_amplitude(i);
    higher += a * a;
  }
  const double a1 = harmonic_amplitude(1);
  if (a1 <= 0.0) return higher > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return std::sqrt(higher) / a1;
}

double HarmonicObserver::output_estimate() const noexcept { return output_row().dot(z_); }

std::complex<double> HarmonicObserver::first_harmonic(double x1, double x2) const noexcept {
  // z1 = A1 sin(theta + phi1), z2 = A1 cos(theta + phi1) with x1 = sin(theta), x2 = cos(theta).
  const double re = x1 * z_(0) + x2 * z_(1);  // A1 cos(phi1)
  const double im = x2 * z_(0) - x1 * z_(1);  // A1 sin(phi1)
  return {re, im};
}

}  // namespace servotwin::frf
