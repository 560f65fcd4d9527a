#pragma once
/// \file
/// Swept-sine excitation (dissertation C5.1, discrete form of Sec. 5.6): an exact discrete
/// rotation of the state x = (sin theta, cos theta), so changing omega never makes the signal
/// jump (bumpless), and frequency schedules for linear and logarithmic sweeps.

namespace servotwin::frf {

/// Oscillator x(k+1) = [[cos wTs, sin wTs], [-sin wTs, cos wTs]] x(k), x(0) = (0, 1), so
/// x1(k) = sin(theta_k), x2(k) = cos(theta_k) with theta_{k+1} = theta_k + omega_k Ts. The
/// output is y(k) = A x1(k) + u0. Allocation- and exception-free after construction.
class SineGenerator {
 public:
  /// ts: sample period [s]; throws core::InputError (field "ts") unless finite and > 0.
  explicit SineGenerator(double ts);

  /// Phase back to 0: x = (0, 1).
  void reset() noexcept;
  /// Frequency used by the next advance() [rad/s]; the rotation is recomputed only when it
  /// changes. Any finite value is accepted (negative runs backwards).
  void set_frequency(double omega) noexcept;
  /// A x1(k) + u0 for the current sample.
  [[nodiscard]] double output(double amplitude, double offset) const noexcept { return amplitude * x1_ + offset; }
  /// Advances to the next sample by rotating x through omega Ts. The norm is pulled back to 1
  /// every sample by one Newton step of x <- x (3 - |x|^2)/2, which keeps |x| = 1 to a few ulps
  /// indefinitely without touching the phase.
  void advance() noexcept;

  [[nodiscard]] double sin_phase() const noexcept { return x1_; }  ///< x1 = sin(theta)
  [[nodiscard]] double cos_phase() const noexcept { return x2_; }  ///< x2 = cos(theta)
  [[nodiscard]] double frequency() const noexcept { return omega_; }
  [[nodiscard]] double sample_period() const noexcept { return ts_; }

 private:
  double ts_;
  double omega_ = 0.0;
  double c_ = 1.0, s_ = 0.0;  // cos, sin of omega Ts
  double x1_ = 0.0, x2_ = 1.0;
};

/// Sweep law.
enum class SweepType {
  kLinear,       ///< omega(k+1) = omega(k) + rate, rate in rad/s per sample (the document's "cp")
  kLogarithmic,  ///< omega(t) = omega_b e^{rate t}, rate = sweep coefficient sc [1/s]
};

/// Frequency schedule of a sweep towards omega_end.
class SweepSchedule {
 public:
  /// Throws core::InputError (field "sweep_rate", "ts" or "omega_end") unless rate, ts and
  /// omega_end are finite and > 0.
  SweepSchedule(SweepType type, double rate, double ts, double omega_end);
  /// The frequency one sample after omega, never beyond omega_end.
  [[nodiscard]] double next(double omega) const noexcept;
  /// Samples needed to sweep from omega_begin to omega_end (for planning and tests).
  [[nodiscard]] double samples_between(double omega_begin, double omega_end) const noexcept;
  [[nodiscard]] SweepType type() const noexcept { return type_; }

 private:
  SweepType type_;
  double rate_;
  double growth_;  // e^{rate ts} for the logarithmic sweep
  double ts_;
  double omega_end_;
};

}  // namespace servotwin::frf
