#pragma once
// notch:auto (issue 25 §5): which mode a notch at the PI's output should take, and the candidate
// notches the tuner's bandwidth search tries on it.

#include <optional>
#include <string>
#include <vector>

#include "servotwin/tuning/drive_filter.hpp"
#include "servotwin/tuning/normalized_plant.hpp"

namespace servotwin::tuning::detail {

/// The resonance a notch should take (normalized frequency and damping) and why.
struct NotchTarget {
  double omega = 0.0;  ///< normalized resonance frequency (ω/ωz)
  double zeta = 0.0;   ///< the resonance's damping
  std::string reason;
};

/// The mode the PI cannot damp: the first higher mode the motor sees (C7.16: a PI/PID acts on the
/// first mode only), else the first mode when r lies outside √3..√5 (C7.4: below, the PI cannot
/// damp it to 0.707; above, it is sluggish). std::nullopt when the PI damps every mode itself.
[[nodiscard]] std::optional<NotchTarget> notch_target(const NormalizedPlant& plant);

/// The notches the search tries on `target`: the zeros cancel the resonance's poles (zero damping
/// = the mode's), the poles' damping ζn from a ladder of widths (0.1 … 0.7, those wider than the
/// mode), so the depth is 20 log10(ζn/ζ). Physical frequencies (ωz [rad/s]); only those below the
/// Nyquist frequency of ts.
[[nodiscard]] std::vector<DriveFilterSpec> notch_candidates(const NotchTarget& target, double omega_z, double ts);

}  // namespace servotwin::tuning::detail
