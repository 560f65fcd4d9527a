#pragma once
// Private helpers shared by the shaper designs: argument checks and number formatting for error
// messages (the shaping library does not link fmt).

#include <string>

namespace servotwin::shaping::detail {

/// Throws core::InputError naming "omega" (finite, > 0) or "zeta" ([0, 1)).
void check_design_mode(double omega, double zeta);

/// A number as printed in error messages (%.10g).
std::string show(double value);

}  // namespace servotwin::shaping::detail
