#pragma once
/// \file
/// The ZV4 four-impulse shaper of the dissertation (catalog C6.1–C6.2): zero vibration at the
/// mode, with an intuitive user parametrization p1 (duration / asymmetry), p2 (insensitivity),
/// p3 (additional, only for p1 = 0), and the preset table (Table 6.1).
///
/// Algorithm (C6.2, with the published misprint fixed: a3 = max{a2 − 1, p3/(1−p3)} for p1 = 0):
///   α = p1·2π/3; for 0 < |α| ≤ π/2: a2 = max(0, 2cos|α|) + p2/(1−p2); for π/2 < |α| ≤ 2π/3:
///   a2 = max(0, sin3|α|/sin2|α|)·p2; a3 = (a2 sin2|α| − sin3|α|)/sin|α|,
///   a4 = (a2 sin|α| − sin2|α|)/sin|α|. For p1 = 0: a2 = p2/(1−p2), a3 = max{a2−1, p3/(1−p3)},
///   a4 = 1 − a2 + a3. Spacing T = (π − α)/ω_d (signed α), t_i = 0, T, 2T, 3T,
///   A_i ∝ a_i e^{−ζω t_i}, ΣA = 1.
/// Impulses whose amplitude is zero (e.g. a3 = a4 = 0 for the ZV preset, a4 = 0 on the boundary
/// p2 = 0 or at p1 = ±1) are dropped, so the presets give the classic 2-, 3- and 4-impulse
/// shapers with their true durations. Amplitudes below 1e-12 of the largest are rounding noise of
/// the trigonometric formulas at the region edges (e.g. sin 3α at α = 2π/3) and count as zero.

#include <string>
#include <string_view>
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping {

/// The user parameters of C6.2.
struct Zv4Parameters {
  double p1 = 0.0;  ///< duration/asymmetry, [−1, 1]: t_last = 2.5 T_d (−1), 1.5 T_d (0), 0.5 T_d (1)
  double p2 = 0.5;  ///< insensitivity, [0, 1); for p1 ≠ 0 the range (0.5, 1) mirrors (0, 0.5)
  double p3 = 0.0;  ///< additional, [0, 1); only meaningful when p1 = 0 (must be 0 otherwise)
};

/// Designs the ZV4 shaper for a mode. Throws core::InputError naming the value when omega is not
/// finite and > 0, zeta is outside [0, 1), p1 outside [−1, 1], p2 or p3 outside [0, 1), or p3 ≠ 0
/// with p1 ≠ 0 (p3 has no effect there, so a non-zero value is a mistake).
Shaper zv4_shaper(double omega, double zeta, const Zv4Parameters& parameters);

/// A row of Table 6.1.
struct Zv4Preset {
  std::string name;  ///< "zv", "zvd", "zvdd", "2hei5", "2hei2", "2hei1"
  Zv4Parameters parameters;
  std::string note;  ///< what the row reproduces
};

/// Table 6.1 (p1 = 0 throughout). The 2-hump rows give humps of V_tol for ζ = 0 only. The 5 % and
/// 1 % rows are the printed values (humps 5.01 % and 1.00 %); the printed 2 % row (0.7075) gives a
/// 2.49 % hump, so the value giving 2 % (0.713573, the closed-form 2-hump EI solved in tools/reference/shaping_reference.py)
/// is used instead (catalog §5 defect 2).
[[nodiscard]] const std::vector<Zv4Preset>& zv4_presets();
/// Looks a preset up by name; throws core::InputError naming `field` and listing the names.
[[nodiscard]] Zv4Parameters zv4_preset(std::string_view name, std::string_view field = "preset");

}  // namespace servotwin::shaping
