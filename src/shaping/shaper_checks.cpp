#include "shaper_checks.hpp"

#include <cmath>
#include <cstdio>

#include "servotwin/core/error.hpp"

namespace servotwin::shaping::detail {

void check_frequency(double omega, const std::string& field) {
  if (!std::isfinite(omega) || omega <= 0.0)
    throw core::InputError(core::at_field(field), "expected a finite frequency > 0 rad/s, got " + show(omega));
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
