#pragma once
// What `servotwin tune` (and later `simulate`) reads as "the plant": a fitted plant-model file, a
// plant description file, or a built-in flexible preset, turned into the fitted-model type the
// tuner works on plus the known HF dynamics the description carries.

#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/transfer_function.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/tuning/normalized_plant.hpp"

namespace servotwin::cli {

/// A plant ready for tuning.
struct TunePlant {
  fit::PlantModel model;
  tuning::HfDynamics hf;            ///< from a plant description: current lag, delay + half a sample
  std::optional<double> ts;         ///< a plant description's sample period
  std::vector<std::string> notes;   ///< what was set aside (friction, backlash, ...)
  bool fitted = false;              ///< read from a fitted plant-model file (residuals make sense)
  /// The plant description (file or preset) itself, nonlinearities included: the design is
  /// verified on it by simulation.
  std::optional<machine::PlantConfig> description;
};

/// Reads `name_or_path`: a servotwin.plant-model/1 file, a servotwin.plant/1 file or a flexible
/// preset name (servotwin machine --list-flexible). core::InputError names the file and field.
TunePlant load_tune_plant(const std::string& name_or_path);

/// The whole of `text` as a finite number, or std::nullopt.
std::optional<double> parse_number(const std::string& text);

/// "auto" (std::nullopt) or a number >= 0 (> 0 unless `zero_ok`) for option `flag`; core::InputError
/// naming the flag and `what` was expected otherwise.
std::optional<double> parse_auto(const std::string& text, const char* flag, bool zero_ok, const char* what);

/// Parses a coefficient list "2.6, 0" or "2.6 0" (descending powers of s) for option `option`.
core::Polynomial parse_coefficients(const std::string& text, const std::string& option);

}  // namespace servotwin::cli
