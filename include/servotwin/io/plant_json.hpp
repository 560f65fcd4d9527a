#pragma once
/// \file
/// Plant description JSON, format "servotwin.plant/1": the simulated plant an identification
/// experiment runs on (machine::PlantConfig). Three types:
///
///   {"format": "servotwin.plant/1", "type": "two-mass",
///    "motor_inertia": .., "load_inertia": .., "stiffness": .., "damping": ..,
///    "motor_viscous": .., "load_viscous": .., "coulomb": .., "backlash": .., "noise_std": .., "ts": ..}
///     - all of these are required; "coulomb" is the load's Coulomb level TC (the Karnopp friction
///       of catalog C5.10 sits on the load); optional "stiction" (load TS, default = coulomb),
///       "motor_coulomb", "motor_stiction", "stick_band" (dv, both masses).
///   {"type": "mass-chain", "inertias": [n], "stiffnesses": [n-1], "dampings": [n-1],
///    optional "viscous": [n], "coulomb": [n], "stiction": [n], "stick_band": number,
///    "backlash": [n-1], and "noise_std", "ts"}
///   {"type": "transfer-function", "num": [..], "den": [..] (highest power first), "noise_std", "ts"}
///
/// Optional for every type: "name", "description", "output" (motor_velocity | motor_position |
/// load_velocity | load_position, default motor_velocity), "current_lag" [s], "delay_samples",
/// "quantization", "seed", "substeps". Unknown fields are errors (usually typos). Every error is a
/// core::InputError naming the source and the field (line:column for JSON syntax errors).

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "servotwin/machine/flexible_plant.hpp"

namespace servotwin::io {

inline constexpr std::string_view kPlantFormat = "servotwin.plant/1";

/// Parses a plant description.
machine::PlantConfig parse_plant_json(std::string_view text, std::string_view source_name);

/// A flexible-plant preset name (machine::flexible_preset_names), or else a path to a plant file.
machine::PlantConfig load_plant(const std::string& name_or_path);

/// Full description; round-trips through parse_plant_json. A two-mass chain whose only friction
/// is Karnopp friction with one common stick band is written as "two-mass", any other chain as
/// "mass-chain". Throws core::InputError for a configuration that validate() rejects.
nlohmann::json plant_to_json(const machine::PlantConfig& plant);

}  // namespace servotwin::io
