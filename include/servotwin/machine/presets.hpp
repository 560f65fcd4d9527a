#pragma once
/// \file
/// Named virtual machines. The Fadal VMC 2216 presets reproduce the "actual" closed-loop columns
/// of thesis Tables 3.3 (P-PI), 3.4 (PID) and 3.5 (sliding mode) exactly; `ballscrew-zpetc` is
/// the ball-screw drive of thesis section 3.4.2 (pole placement at 30 Hz / 0.7 with a Kalman
/// disturbance observer and ZPETC, ts = 1 ms).

#include <string>
#include <string_view>
#include <vector>

#include "servotwin/machine/axis_config.hpp"

namespace servotwin::machine {

/// Names of all presets: fadal-ppi, fadal-pid, fadal-smc, ballscrew-zpetc.
std::vector<std::string> preset_names();
/// The preset with that name; throws core::InputError listing the known names otherwise.
MachineConfig preset(std::string_view name);

}  // namespace servotwin::machine
