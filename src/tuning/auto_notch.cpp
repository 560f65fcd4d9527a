#include "auto_notch.hpp"

#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "servotwin/tuning/hinf.hpp"

namespace servotwin::tuning::detail {

namespace {
// C7.4: the PI damps the mode actively for √3 <= r <= √5.
const double kSweetSpotLow = std::sqrt(3.0), kSweetSpotHigh = std::sqrt(5.0);
// The notch poles' dampings tried: from a narrow notch (little phase lag below it, sensitive to
// a shifted mode) to a wide one (robust to the mode's shift, more phase lag at the crossover).
constexpr double kNotchDampings[] = {0.1, 0.2, 0.35, 0.5, 0.7};
// Below this depth a candidate is no notch at all (its poles barely wider than the mode).
constexpr double kMinDepthRatio = 1.5;
// A resonance with a damping this small is taken as this (a depth of 20 log10(ζn/0.002) already
// exceeds 30 dB; a deeper notch only gains sensitivity to the mode's frequency).
constexpr double kMinModeDamping = 0.002;
}  // namespace

std::optional<NotchTarget> notch_target(const NormalizedPlant& plant) {
  for (std::size_t i = 0; i < plant.higher_modes.size(); ++i) {
    const fit::Mode& m = plant.higher_modes[i];
    if (practically_unobservable(m)) continue;
    return NotchTarget{m.resonance.omega_rad_s, m.resonance.zeta,
                       fmt::format("mode {} (a higher mode: the PI acts on the first mode only, catalog C7.16)", i + 2)};
  }
  if (plant.r < kSweetSpotLow || plant.r > kSweetSpotHigh)
    return NotchTarget{plant.r, plant.zeta_p,
                       fmt::format("the first resonance (r = {:.3g} outside sqrt(3)..sqrt(5): the PI cannot damp it, "
                                   "catalog C7.4)",
                                   plant.r)};
  return std::nullopt;
}

std::vector<DriveFilterSpec> notch_candidates(const NotchTarget& target, double omega_z, double ts) {
  std::vector<DriveFilterSpec> out;
  const double f = target.omega * omega_z / (2.0 * std::numbers::pi);
  if (!(f < 0.5 / ts)) return out;
  const double zeta = std::max(target.zeta, kMinModeDamping);
  for (const double zn : kNotchDampings) {
    if (zn < kMinDepthRatio * zeta) continue;
    DriveFilterSpec s;
    s.type = DriveFilterType::kNotch;
    s.frequency_hz = f;
    s.width_hz = 2.0 * zn * f;
    s.depth_db = 20.0 * std::log10(zn / zeta);
    s.automatic = true;
    out.push_back(s);
  }
  return out;
}

}  // namespace servotwin::tuning::detail
