#pragma once
// Internal: the positive-gain limit of eq. 7.63 with the gain that vanishes there.
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning::detail {

struct GainRoot {
  double omega = 1.0;                               ///< first root in (0, 1], or 1
  RangeLimit limit = RangeLimit::kFullBandwidth;  ///< which gain vanishes there (kFullBandwidth: none)
};

/// frictionless_gain_limit() with the gain (Kp or Ki) whose numerator has that root.
GainRoot frictionless_gain_root(double r, double zeta_z, double zeta_star);

}  // namespace servotwin::tuning::detail
