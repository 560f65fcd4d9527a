#include "shaper_checks.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "servotwin/core/error.hpp"

namespace servotwin::shaping::detail {

/// Mode frequencies a shaper is designed for (issue 27 §3: 1e300 Hz gave a shaper of 5e-301 s
/// whose smoothing measure overflowed in `shaper compare`): from a crane's slow sway to the
/// highest structural mode, 1 mHz to 100 kHz.
constexpr double kMinModeHz = 1e-3, kMaxModeHz = 1e5;

void check_frequency(double omega, const std::string& field) {
  if (!std::isfinite(omega) || omega <= 0.0)
    throw core::InputError(core::at_field(field), "expected a finite frequency > 0 rad/s, got " + show(omega));
  const double hz = omega / (2.0 * std::numbers::pi);
  if (hz < kMinModeHz || hz > kMaxModeHz)
    throw core::InputError(core::at_field(field), "expected a mode frequency from " + show(kMinModeHz) + " to " +
                                                      show(kMaxModeHz) + " Hz, got " + show(hz) + " Hz (" + show(omega) +
                                                      " rad/s)");
}

void check_damping(double zeta, const std::string& field) {
  if (!std::isfinite(zeta) || zeta < 0.0 || zeta >= 1.0)
    throw core::InputError(core::at_field(field), "expected a damping ratio in [0, 1), got " + show(zeta));
}

void check_design_mode(double omega, double zeta) {
  check_frequency(omega, "omega");
  check_damping(zeta, "zeta");
}

std::string show(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

}  // namespace servotwin::shaping::detail
