#pragma once
/// \file
/// Discrete-time 11-state harmonic observer (dissertation C5.2, C5.5, C5.6): DC plus harmonics
/// 1..5 of the current excitation frequency, discretized by Tustin prewarped at that frequency,
/// updated in O(n) per sample, allocation- and exception-free.
///
/// Discretization. The continuous observer is z' = omega (A_cl z + k1 y) with
/// A_cl = A_o(1) - k1 C_o. Tustin with prewarp at omega (T' = 2 tan(omega Ts/2)/omega) gives the
/// trapezoid rule in lambda = integral of omega with half-step gamma = omega T'/2 = tan(omega Ts/2):
///   (I - gamma A_cl) z(k+1) = (I + gamma A_cl) z(k) + gamma k1 (y(k+1) + y(k)).
/// It is realized with the state w(k) = (I - gamma A_cl) z(k) - gamma k1 y(k):
///   z(k) = (I - gamma A_cl)^-1 (w(k) + gamma k1 y(k)),   w(k+1) = 2 z(k) - w(k),
/// which for a frozen omega is the document's balanced realization (Phi, Gamma, H, J) with its
/// state scaled by sqrt(T') (see tustin_realization()); while omega changes (sweep) each half
/// step uses its own gamma, so z keeps its meaning (the "implementation alternative" of C5.6).
///
/// Fast inverse. I - gamma A_cl = D + gamma k1 C_o with D = I - gamma A_o(1) block diagonal
/// (2x2 blocks [[1, -i gamma], [i gamma, 1]] and 1), so the solve is Sherman–Morrison:
///   x = D^-1 r - D^-1 k1 * gamma (C_o D^-1 r) / (1 + gamma C_o D^-1 k1),
/// about 100 flops instead of an 11x11 LU.

#include <complex>

#include "servotwin/frf/observer_gains.hpp"

namespace servotwin::frf {

/// The document's balanced Tustin matrices at a frozen frequency (C5.6): x(k+1) = Phi x + Gamma y,
/// z(k) = H x + J y. Dense reference formula (uses an 11x11 inverse; not for the per-sample path).
struct TustinRealization {
  ObserverMatrix phi;
  ObserverVector gamma;
  ObserverMatrix h;
  ObserverVector j;
};
TustinRealization tustin_realization(const ObserverVector& k1, double omega, double ts);

/// The harmonic observer. Construct once per gain design and sample period; feed one measured
/// sample per call to update().
class HarmonicObserver {
 public:
  /// k1: unit-frequency gain (design_gains()); ts: sample period [s]. Throws core::InputError
  /// (field "ts" or "k1") for a non-positive/non-finite ts or a non-finite gain.
  HarmonicObserver(const ObserverVector& k1, double ts);

  /// Clears the state (all estimates 0).
  void reset() noexcept;
  /// Sets the state so that the estimate is the constant `dc` (no harmonics) for a measurement
  /// that stays at `dc`: a bumpless start when the output already sits at a working point.
  void reset_to_dc(double dc) noexcept;

  /// One sample: y is the measured output at sample k, omega the generator frequency at sample k
  /// [rad/s], required 0 < omega < pi/ts (not checked: hot path; the RFID block guarantees it and
  /// keeps 5 omega below Nyquist). Afterwards estimate() is z(k).
  void update(double y, double omega) noexcept;

  /// z(k): (sin, cos) pairs of harmonics 1..5, then DC.
  [[nodiscard]] const ObserverVector& estimate() const noexcept { return z_; }
  /// A0 = z11, the DC level (signed).
  [[nodiscard]] double dc() const noexcept { return z_(kDcState); }
  /// Ai = sqrt(z_{2i-1}^2 + z_{2i}^2), i = 1..5; i = 0 gives |A0|.
  [[nodiscard]] double harmonic_amplitude(int i) const noexcept;
  /// THD = sqrt(A2^2 + ... + A5^2) / A1 (C5.11); +infinity when A1 = 0 with harmonics present, 0 when all vanish.
  [[nodiscard]] double thd() const noexcept;
  /// Output estimate y_hat(k) = C_o z(k).
  [[nodiscard]] double output_estimate() const noexcept;
  /// A1 e^{j phi1}: amplitude and phase of the first harmonic relative to the generator states
  /// x1 = sin(theta), x2 = cos(theta) of the same sample (eqs. 5.9–5.11 with both misprints fixed:
  /// A1 cos(phi1) = x1 z1 + x2 z2, A1 sin(phi1) = x2 z1 - x1 z2, phi1 = atan2(sin, cos)).
  /// Dividing by the excitation amplitude gives the response point P(j omega).
  [[nodiscard]] std::complex<double> first_harmonic(double x1, double x2) const noexcept;

  [[nodiscard]] const ObserverVector& gains() const noexcept { return k1_; }
  [[nodiscard]] double sample_period() const noexcept { return ts_; }

 private:
  /// x = (I - gamma A_cl)^-1 r by Sherman–Morrison (see the file comment).
  void solve_shifted(const ObserverVector& r, ObserverVector& x) const noexcept;
  void set_frequency(double omega) noexcept;

  ObserverVector k1_;
  double ts_;
  double omega_ = -1.0;      // frequency gamma_ belongs to (-1: none yet)
  double gamma_ = 0.0;       // tan(omega ts / 2)
  ObserverVector dinv_k_;    // D^-1 k1 for the current gamma
  double sm_denominator_ = 1.0;  // 1 + gamma C_o D^-1 k1
  ObserverVector w_;         // Tustin state
  ObserverVector z_;         // estimate
  ObserverVector scratch_;
};

}  // namespace servotwin::frf
