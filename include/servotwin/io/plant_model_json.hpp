#pragma once
/// \file
/// The fitted plant model file "servotwin.plant-model/1" (written by `servotwin fit`):
///
///     {"format": "servotwin.plant-model/1",
///      "model": {"type": "rigid"|"two-mass"|"multi-mode", "output": "velocity"|"position",
///                "rigid": "pole"|"integrator", "gain", "gain_std",
///                "rigid_pole_hz", "rigid_pole_hz_std"            (null for the integrator),
///                "lag_pole_hz", "lag_pole_hz_std", "delay_s", "delay_s_std"   (null when absent),
///                "numerator": [...], "denominator": [...]}       (s in rad/s, highest power first,
///                                                                  delay excluded)
///      "modes": [{"mode": 1, "kind": "antiresonance"|"resonance", "freq_hz", "zeta",
///                 "freq_hz_std", "zeta_std"}, ...],             (two entries per mode)
///      "physical": {"motor_inertia", "motor_inertia_std", "load_inertia", "load_inertia_std",
///                   "stiffness", "stiffness_std", "damping", "damping_std",
///                   "resonance_ratio", "resonance_ratio_std", "damping_consistency"} or null,
///      "physical_note": "...",
///      "fit": {"converged", "message", "initialization", "weighting", "points", "parameters",
///              "iterations", "cost", "residual" (rms of |ln(P_model/P_meas)|), "sigma2",
///              "left_out": ["1 Hz: THD 0.155 above 0.07 ...", ...] (points marked invalid, not fitted)},
///      "nonlinear": {"coulomb": {"estimated", "level", "level_std", "significant", "frequencies",
///                                "points", "note"},
///                    "backlash": {"estimated", "significant", "width", "stiffness", "note",
///                                 "runs": [{"amplitude", "antiresonance_hz", "antiresonance_hz_std",
///                                           "effective_stiffness", "twist_amplitude"}]}}
///                   (only when responses at several amplitudes were given; read back as a record),
///      "friction": {"model": "two-mass, Coulomb on motor and load", "motor_coulomb",
///                   "motor_coulomb_std", "load_coulomb", "load_coulomb_std", "viscous_damping",
///                   "viscous_damping_std", "residual", "linear_residual", "note"}
///                   (`fit --friction`: "model", "modes" and "physical" then hold the linear part),
///      "selection": {"method", "criterion", "chosen_modes", "candidates": [{"modes",
///                    "parameters", "converged", "cost", "score"}],
///                    "output_detection": {"output", "detected", "slope_db_per_decade", "note"}}}
///
/// Standard deviations that are not identifiable are written as null. The reader needs "format",
/// "model" and "modes"; "numerator"/"denominator" must agree with the modal parameters
/// (relative 1e-6), so a hand-edited file cannot silently mean two different plants.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "servotwin/fit/fit.hpp"
#include "servotwin/fit/friction_fit.hpp"
#include "servotwin/fit/nonlinear.hpp"

namespace servotwin::io {

inline constexpr std::string_view kPlantModelFormat = "servotwin.plant-model/1";

/// The whole report as a plant-model document; `friction` (a fitted CoulombFit) adds its record.
nlohmann::json plant_model_to_json(const fit::FitReport& report, const fit::NonlinearMechanics* nonlinear = nullptr,
                                   const fit::CoulombFit* friction = nullptr);

/// What a plant-model file gives back.
struct LoadedPlantModel {
  fit::PlantModel model;
  std::optional<fit::TwoMassParameters> physical;
  std::string physical_note;
};

/// Reads a plant-model document; core::InputError names the source and the field ("modes[2].zeta").
LoadedPlantModel parse_plant_model_json(std::string_view text, std::string_view source_name);
/// True when `path` is a regular file holding a JSON object whose "format" is
/// servotwin.plant-model/1 (false for anything else, without error: the caller then reads it as
/// another kind and reports what is wrong with it).
bool is_plant_model_file(const std::string& path);
/// Opens and reads a plant-model file.
LoadedPlantModel load_plant_model(const std::string& path);

}  // namespace servotwin::io
