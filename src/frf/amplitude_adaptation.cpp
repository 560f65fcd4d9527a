#include "servotwin/frf/amplitude_adaptation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace servotwin::frf {

void AmplitudeAdapter::reset() noexcept {
  amplitude_ = std::clamp(law_.initial, 0.0, law_.maximum);
  relay_ = thd_relay_ = snr_relay_ = false;
  action_ = AmplitudeAction::kHold;
}

void AmplitudeAdapter::set_amplitude(double amplitude) noexcept {
  amplitude_ = std::clamp(amplitude, 0.0, law_.maximum);
}

double AmplitudeAdapter::update(double thd, double usage, double omega_ts, double snr) noexcept {
  if (thd > law_.thd_threshold + law_.thd_hysteresis) thd_relay_ = true;
  else if (thd < law_.thd_threshold - law_.thd_hysteresis) thd_relay_ = false;
  // NaN THD (no first harmonic yet) leaves the relay as it was.
  // The SNR's own relay with its own hysteresis: a THD inside its band must not keep an SNR demand
  // on. Unknown SNR (NaN) leaves it as it was; without SNR* it never switches on.
  if (law_.snr_minimum > 0.0 && snr == snr) {
    if (snr < law_.snr_minimum) snr_relay_ = true;
    else if (snr > law_.snr_minimum * (1.0 + law_.snr_hysteresis)) snr_relay_ = false;
  }
  relay_ = thd_relay_ || snr_relay_;

  const double periods = std::abs(omega_ts) / (2.0 * std::numbers::pi);  // fraction of a period per sample
  const bool usage_unknown = !(usage == usage);  // NaN: be conservative, never increase
  if (usage_unknown || usage >= law_.reduce_ratio) {
    action_ = usage_unknown ? AmplitudeAction::kHold : AmplitudeAction::kDecrease;
    if (!usage_unknown)
      amplitude_ = std::min(amplitude_, std::max(law_.minimum, amplitude_ * std::pow(law_.reduce_per_period, periods)));
  } else if (usage >= law_.hold_ratio * law_.reduce_ratio || !relay_ || amplitude_ >= law_.maximum) {
    action_ = AmplitudeAction::kHold;
  } else {
    action_ = AmplitudeAction::kIncrease;
    // The fast growth only while the SNR demands it (a stuck motor: no response to measure); a
    // THD demand alone keeps rc per period, since the THD estimate lags a fast-changing amplitude
    // and the relay would overshoot (tried: the frictionless bench went from 25 to 31 s).
    if (law_.proportional)
      amplitude_ *= std::max(std::pow(1.0 + law_.rate, periods), snr_relay_ ? per_sample_growth_ : 1.0);
    else amplitude_ += law_.rate * law_.initial * periods;
  }
  amplitude_ = std::clamp(amplitude_, 0.0, law_.maximum);
  return amplitude_;
}

}  // namespace servotwin::frf
