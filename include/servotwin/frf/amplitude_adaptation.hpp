#pragma once
/// \file
/// Excitation-amplitude adaptation of the identification experiment (dissertation C5.11):
/// an integrator driven by a relay with hysteresis on the THD raises the amplitude while the
/// response is distorted or noisy; range protection holds or lowers it when the measured output
/// or the actuator command approaches its limit. Arbitration: decrease > hold > increase.

#include <cmath>
#include <limits>

namespace servotwin::frf {

/// Settings of the amplitude law (validated by the owner, see RfidParameters).
struct AmplitudeLaw {
  double initial = 1.0;         ///< A(t0); the integrator's step is relative to it
  double maximum = 1.0;         ///< hard ceiling, never exceeded
  double minimum = 0.0;         ///< floor of the range reduction (keeps the experiment alive)
  double rate = 0.2;            ///< rc: relative change per excitation period, increment rc A(t0) per period
  double thd_threshold = 0.1;   ///< THD*
  double thd_hysteresis = 0.02; ///< h: relay on above THD* + h, off below THD* - h
  /// SNR*: a second relay, on while the point's SNR is below it (issue 25 §1: "the amplitude rises
  /// until THD and SNR meet their limits"), off above SNR*·(1 + snr_hysteresis); the amplitude
  /// rises while either relay is on. 0: the THD alone drives the amplitude (the document's law).
  double snr_minimum = 0.0;
  double snr_hysteresis = 0.5;
  double hold_ratio = 0.9;      ///< hold when the limit usage exceeds hold_ratio * reduce_ratio
  double reduce_ratio = 0.8;    ///< decrease when the limit usage exceeds this fraction
  double reduce_per_period = 0.5;  ///< amplitude factor per period while decreasing
  /// false: the document's integrator, rc A(t0) per period (a constant step: slow when the
  /// amplitude an antiresonance needs is many times A(t0)); true: rc A(t) per period, i.e. the
  /// amplitude grows by the factor (1 + rc) per period (the same time to double from any level).
  bool proportional = false;
  /// With `proportional`, the least growth per second while the SNR relay is on: the amplitude
  /// grows by at least the factor (1 + growth_per_second) per second of excitation (0: by (1 + rc)
  /// per period only). At low frequencies a period is long and rc = 0.1 per period takes 18 s at
  /// 1 Hz to raise the amplitude 5.5 times, what a motor held by Coulomb friction above the
  /// excitation's level needs before it moves at all (issue 25 §1's 30 s).
  double growth_per_second = 0.0;
  double ts = 0.0;  ///< sample period [s], for growth_per_second (0: growth_per_second does not act)
};

/// What the arbitration decided in the last update.
enum class AmplitudeAction { kHold, kIncrease, kDecrease };

/// The amplitude law, one update per sample, allocation- and exception-free.
class AmplitudeAdapter {
 public:
  explicit AmplitudeAdapter(const AmplitudeLaw& law) noexcept
      : law_(law), amplitude_(law.initial), per_sample_growth_(std::pow(1.0 + law.growth_per_second, law.ts)) {}

  /// Back to A(t0), relay off.
  void reset() noexcept;
  /// One sample. thd: current THD estimate; usage: how much of the allowed range is used
  /// (max over the output range and the actuator headroom, 1 = at the limit); omega_ts: excitation
  /// phase advance per sample [rad]; snr: the response's current SNR (+inf or NaN: unknown, no
  /// SNR demand). Returns the new amplitude, always in [minimum, maximum].
  double update(double thd, double usage, double omega_ts,
                double snr = std::numeric_limits<double>::infinity()) noexcept;
  /// Forces the amplitude (clamped to [0, maximum]), e.g. for the final ramp-out.
  void set_amplitude(double amplitude) noexcept;

  [[nodiscard]] double amplitude() const noexcept { return amplitude_; }
  [[nodiscard]] AmplitudeAction last_action() const noexcept { return action_; }
  /// Relay output r: true while the THD (or the SNR) asks for more amplitude.
  [[nodiscard]] bool relay() const noexcept { return relay_; }
  /// True when the THD wants more amplitude but the ceiling or the range protection blocks it.
  [[nodiscard]] bool blocked() const noexcept { return relay_ && action_ != AmplitudeAction::kIncrease; }
  [[nodiscard]] const AmplitudeLaw& law() const noexcept { return law_; }

 private:
  AmplitudeLaw law_;
  double amplitude_;
  double per_sample_growth_;  ///< (1 + growth_per_second)^ts, the SNR-driven growth per sample
  bool relay_ = false, thd_relay_ = false, snr_relay_ = false;
  AmplitudeAction action_ = AmplitudeAction::kHold;
};

}  // namespace servotwin::frf
