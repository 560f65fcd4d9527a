#pragma once
// Private helpers shared by the shaper designs: argument checks and number formatting for error
// messages (the shaping library does not link fmt).

#include <string>

namespace servotwin::shaping::detail {

/// Throws core::InputError naming `field` unless omega is a finite frequency > 0 [rad/s].
void check_frequency(double omega, const std::string& field);

/// Throws core::InputError naming `field` unless zeta is a damping ratio in [0, 1).
void check_damping(double zeta, const std::string& field);

/// check_frequency(omega, "omega") and check_damping(zeta, "zeta").
void check_design_mode(double omega, double zeta);

/// A number as printed in error messages (%.10g).
std::string show(double value);

}  // namespace servotwin::shaping::detail
