#pragma once
/// \file
/// Files of rapid identification: the sufficient statistics ("servotwin.normal-equations/1") and
/// the identified axis model ("servotwin.axis-model/1"). Schemas in docs/file-formats.md.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "servotwin/rapid/axis_model.hpp"
#include "servotwin/rapid/regression.hpp"
#include "servotwin/rapid/solver.hpp"
#include "servotwin/vcnc/identification.hpp"

namespace servotwin::io {

inline constexpr std::string_view kNormalEquationsFormat = "servotwin.normal-equations/1";
inline constexpr std::string_view kAxisModelFormat = "servotwin.axis-model/1";

/// {"format", "regressors", "P", "R", "Gamma", "N", "Ts"} plus context: "command_shift" (the
/// shift the regressors were built with; a model solved from them is simulated with it) and, when
/// given, "axis" and "sources".
nlohmann::json normal_equations_to_json(const rapid::NormalEquations& ne, const std::string& axis = {},
                                        const std::vector<std::string>& sources = {}, int command_shift = 0);

/// Reads one statistics file. The regressor list must be exactly rapid::kRegressorNames;
/// errors name the file and the field (e.g. "P[3][4]"). `axis` receives the optional "axis" member,
/// `command_shift` the optional "command_shift" (0 when absent).
rapid::NormalEquations parse_normal_equations_json(std::string_view text, std::string_view source_name,
                                                   std::string* axis = nullptr, int* command_shift = nullptr);

/// Statistics of several files added up (concatenated experiments).
struct LoadedStatistics {
  rapid::RegressionProblem problem;
  std::string axis;  ///< common "axis" of the files (empty when none says)
  int command_shift = 0;  ///< common "command_shift" of the files
  /// Repairs made while reading, each naming its file (a Gamma below R^T P^+ R: see
  /// rapid::RegressionProblem::from_normal_equations).
  std::vector<std::string> warnings;
};
/// Reads and adds up several statistics files; core::InputError naming the file whose Ts, axis or
/// command shift differs from the first's.
LoadedStatistics load_statistics(const std::vector<std::string>& paths);

/// The model file (format, axis, ts, model, search, poles, zeros, bounds, active_constraints,
/// objective, lower_bound, fit, validation, solver, regressors, sources).
nlohmann::json axis_model_to_json(const vcnc::AxisIdentification& record);

/// What later steps need from a model file: axis, ts and the coefficients (poles etc. are
/// recomputed). Errors name the file and the field.
struct LoadedAxisModel {
  std::string axis;
  rapid::AxisModel model;
  std::string method;
  int command_shift = 0;  ///< regressors.command_shift: simulate the model with the same shift
};
LoadedAxisModel parse_axis_model_json(std::string_view text, std::string_view source_name);
LoadedAxisModel load_axis_model(const std::string& path);

}  // namespace servotwin::io
