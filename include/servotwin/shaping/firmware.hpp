#pragma once
/// \file
/// Shapers as 3D-printer and CNC firmwares compute them for themselves. Klipper and RepRapFirmware
/// take a shaper by name, frequency and damping and compute its impulses with their own formulas
/// (RepRapFirmware also takes an impulse table, `M593 P"custom"`); an exported servotwin design
/// is then run as the firmware computes it, which this module reproduces so that the difference
/// can be stated.
///
/// Klipper (klippy/extras/shaper_defs.py, studied, not copied): with ζ the damping, df = √(1−ζ²),
/// K = exp(−ζπ/df) and the damped period t_d = 1/(f·df),
/// * zv: A = [1, K], T = [0, t_d/2]; zvd: A = [1, 2K, K²], T = [0, t_d/2, t_d];
/// * mzv: K' = exp(−0.75 ζπ/df), A = [1 − 1/√2, (√2 − 1) K', (1 − 1/√2) K'²],
///   T = [0, 0.375 t_d, 0.75 t_d];
/// * ei, 2hump_ei, 3hump_ei: Singhose's polynomial curve fits in ζ for a 5 % vibration
///   tolerance (Singhose, Seering & Singer 1997; Klipper's SHAPER_VIBRATION_REDUCTION = 20): ei's
///   times in units of t_d, the hump variants' in units of the undamped period 1/f;
/// amplitudes divided by their sum (Klipper's init_shaper). zv, zvd and mzv equal servotwin's
/// designs (families.hpp); the EI family differs slightly (families.hpp's file comment has the
/// numbers). Klipper limits the damping per type (0.99; ei 0.4, 2hump_ei 0.3, 3hump_ei 0.2).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping {

/// Klipper's shaper types: "zv", "mzv", "zvd", "ei", "2hump_ei", "3hump_ei".
[[nodiscard]] const std::vector<std::string>& klipper_shaper_types();
/// Whether Klipper has a shaper of this family (by its name).
[[nodiscard]] bool klipper_has(std::string_view type) noexcept;
/// The largest damping ratio Klipper accepts for a type (its input_shaper.py).
[[nodiscard]] double klipper_max_damping(std::string_view type);

/// The impulses Klipper computes for `type` at natural frequency omega [rad/s] and damping zeta.
/// core::InputError (field "type", "omega", "zeta") for a type Klipper does not have, omega not
/// finite or <= 0, zeta outside [0, 1).
[[nodiscard]] Shaper klipper_shaper(std::string_view type, double omega, double zeta);

}  // namespace servotwin::shaping
