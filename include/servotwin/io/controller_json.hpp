#pragma once
/// \file
/// The tuned controller file "servotwin.controller/1" (written by `servotwin tune`, read by the
/// simulation and report commands):
///
///     {"format": "servotwin.controller/1", "structure": "pi"|"pid"|"pi+p"|"lqg"|"lqg+p"|"hinf",
///      "loop": "velocity"|"position" (position iff pi+p), "feedback": "motor",
///      "plant": {"source", "omega_z_hz", "motor_inertia", "r", "zeta_z", "zeta_p", "a"},
///      "gains": {"kp", "ki", "kd", "tau", "wp", "wd", "kpp"}        (physical; kpp null unless pi+p;
///                                                                   null for lqg, lqg+p, hinf)
///      "normalized": {the same members, normalized} (null for lqg, lqg+p, hinf),
///      "state_space": {"inputs": ["velocity_reference", "motor_velocity"], "output": "torque",
///                      "A", "B", "C", "D"}                            (physical, continuous)
///      "discrete": {"ts", "method": "tustin", "prewarp_hz" (or null), "A", "B", "C", "D"} or null,
///      "design": {"omega_star", "omega_star_hz", "zeta_star" (null for lqg), "r_target", "ms", "mt",
///                 "omega_star_source"},
///      "predicted": {every member of tuning::LoopIndices (normalized), the frequencies also in Hz
///                    ("bandwidth_motor_hz", "gain_crossover_hz", ...), the times also in seconds
///                    ("settling_time_s", ...), "closed_loop_poles": [[re, im], ...]},
///      "robustness": {"rs", "np", "rp", "rp_tracking" (optional)},
///      "position": {...} (pi+p) or null,
///      "lqg": {"kbw", "kbw_source", "feedforward", "feedforward_source", the weights of
///              tuning::VelocityLqgOptions, "controller_stable", "controller_poles",
///              "compensator": {as "state_space", normalized}} (lqg, lqg+p) or null (may be absent),
///      "hinf": {"omega_0s", "omega_0s_source", "omega_0t", "xi_v", "gamma_optimal", "gamma",
///               "controller_stable", "controller_poles", "compensator"} (hinf) or null (may be absent),
///      "notes": ["..."]}
///
/// Matrices are arrays of rows. Non-finite indices are written as the strings "inf" and "-inf"
/// (e.g. a gain margin when the phase never crosses −180°) and NaN ("undefined", e.g. load-side
/// indices of a plant without a load side) as null; robustness members are null when not
/// evaluated. Every other number must be finite.
///
/// The reader checks the format's major version, every member's type, shape and range, that the
/// loop matches the structure, that the physical gains are the normalized ones de-normalized with
/// the plant scales (tuning::to_physical, Kpp = Kpp_n·ωz; relative 1e-6), that the state spaces
/// realize the controller of the gains (tuning::controller_state_space and
/// tuning::discretize_controller, compared as frequency responses, relative 1e-6; for lqg and hinf the
/// compensator de-normalized, with its listed poles the eigenvalues of its A and its stability
/// flag theirs) and that the
/// derived members (`_hz`, `_s`) agree with the normalized ones. So a hand-edited file cannot
/// silently mean two controllers. Unknown members are errors. Every error is a core::InputError
/// naming the source and the field ("discrete.ts", "state_space.A[1]").

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "servotwin/tuning/controller.hpp"

namespace servotwin::io {

inline constexpr std::string_view kControllerFormat = "servotwin.controller/1";

/// The controller as a document; `plant_source` names the plant-model file it was tuned for ("" when
/// none). Throws std::invalid_argument when a value that must be finite (gains, plant scales, design
/// parameters, state-space matrices, poles) is not, or a PID has kd ≠ 0 with τ = 0 (no state space):
/// such a controller is a programming error, and JSON would otherwise turn the value into null.
nlohmann::json controller_to_json(const tuning::Controller& controller, std::string_view plant_source);

/// What a controller file gives back.
struct LoadedController {
  tuning::Controller controller;
  std::string plant_source;  ///< "plant.source" of the file
};

/// Reads a controller document; core::InputError names the source and the field.
LoadedController parse_controller_json(std::string_view text, std::string_view source_name);
/// Opens and reads a controller file.
LoadedController load_controller(const std::string& path);

}  // namespace servotwin::io
