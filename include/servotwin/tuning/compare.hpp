#pragma once
/// \file
/// The comparison of controller structures of catalog C7.15: every structure tuned to the same
/// spec on the same plant — the largest load bandwidth with ‖S‖∞ <= Ms and ‖ωl/ω*‖∞ <= Mt (1.5
/// and 1.5 in the dissertation) — and compared by the load bandwidth, the load-disturbance peak
/// ‖ωl/Tl‖∞ and the ITAE ∫ t |ωl(t)| dt of a unit load-torque step, each relative to the PI.
///
/// The PID is the virtual-inertia PID of C7.5 at the options' r̄ (2 in C7.15); below r̄ its
/// derivative gain is negative (acceleration feedback), which the comparison allows. A structure
/// that cannot meet the spec is kept with the tuner's message instead of a design.

#include <optional>
#include <string>
#include <vector>

#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/tune.hpp"

namespace servotwin::tuning {

/// One structure of the comparison.
struct StructureComparison {
  Structure structure = Structure::kPi;
  std::optional<TuneResult> result;  ///< the design; std::nullopt when the spec cannot be met
  std::string failure;               ///< the tuner's message then (core::InputError::reason())
};

/// The velocity-loop structures of C7.15 that the tuner offers: pi, pid, lqg, hinf.
[[nodiscard]] std::vector<Structure> comparison_structures();

/// Tunes each of `structures` with `options` (its structure replaced; allow_negative_kd set for
/// the PID). A structure that fails is recorded with its message; when every structure fails (the
/// plant itself: not a flexible drive, r < 1.3; invalid options) the first core::InputError is
/// thrown. A position-loop structure (pi+p) is refused (field "structures": the comparison is of
/// velocity loops).
[[nodiscard]] std::vector<StructureComparison> compare_structures(
    const fit::PlantModel& model, const TuneOptions& options,
    const std::vector<Structure>& structures = comparison_structures());

/// `value` relative to the PI's (value / PI value); NaN without a PI design or a finite, non-zero PI value.
[[nodiscard]] double relative_to_pi(const std::vector<StructureComparison>& comparison,
                                    double LoopIndices::*index, double value);

/// How much worse than the PI's a design's load-step ITAE must be for comparison_notes to say so.
inline constexpr double kFarWorseItae = 3.0;

/// Facts a reader of the comparison must not miss (issue 25 §7): each design whose load-step ITAE
/// is more than kFarWorseItae times the PI's. The spec of C7.15 ranks by load bandwidth at equal
/// peaks, and a design can win it with a weaker integral action: it then tracks faster and rejects
/// a load torque slower, which the table's bandwidth column does not show.
[[nodiscard]] std::vector<std::string> comparison_notes(const std::vector<StructureComparison>& comparison);

}  // namespace servotwin::tuning
