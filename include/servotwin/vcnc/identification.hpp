#pragma once
/// \file
/// Rapid identification of a machine's axes from captures, as the tools run it: regressors over
/// one or more captures (concatenated experiments), the chosen solver, and the simulation-based
/// fit of the identified model on the identification and validation captures.

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/rapid/axis_model.hpp"
#include "servotwin/rapid/refine.hpp"
#include "servotwin/rapid/regression.hpp"
#include "servotwin/rapid/solver.hpp"

namespace servotwin::vcnc {

/// A capture with the name it was read from (for messages).
struct NamedCapture {
  std::string source;
  core::Capture capture;
};

/// Range of command shifts tried when the shift is chosen from the data.
struct ShiftSearch {
  int first = -3, last = 3;
};

struct IdentificationSettings {
  rapid::Method method = rapid::Method::Exact;
  /// Bounds; members left at 0 take the defaults of the capture's ts (thesis section 4.3).
  rapid::Bounds bounds{0.0, 0.0, 0.0, 0.0, 0.2, 2.0};
  /// regressors.command_shift is used as given unless `shift_search` is set.
  rapid::RegressorOptions regressors;
  rapid::SolveOptions solve;
  /// Identify with every command shift in the range and keep the model whose simulated tracking
  /// error fits the identification captures best (stable models first; among fits within 2 % of
  /// the best, the smallest |shift|). The shift absorbs what the continuous model
  /// cannot: a controller's command preview (ZPETC, central-difference feed-forward) or a
  /// transport delay (negative shift). On the presets the fit on the identification data ranks
  /// the shifts exactly as the prediction of other programs does (docs/rapid-identification-study.md).
  std::optional<ShiftSearch> shift_search;
  /// Refine the solver's model by output error (rapid/refine.hpp) on the identification captures,
  /// with the chosen shift: the model that simulates the measured motion best within the bounds.
  bool refine = false;
  rapid::RefineOptions refine_options;  ///< command_shift is set from the identification
  /// Threads the shift search's candidates are solved on (0: every core; the result is the same
  /// for any number).
  std::size_t workers = 0;
};

/// How --shift auto chooses among its trials: of the stable models (all trials when none is stable),
/// the smallest |shift| whose nrmse is within this relative margin of the best (a shift only a
/// little better in fit is more likely noise than delay).
inline constexpr double kShiftFitTolerance = 0.02;

/// One shift tried by the search.
struct ShiftTrial {
  int shift = 0;
  double nrmse = 0.0;  ///< simulated tracking error on the identification captures
  bool stable = false;
  /// false: the simulation stopped once this shift could no longer be chosen (its nrmse already
  /// above the best one's by more than the choice's tolerance); nrmse is then a lower bound.
  bool complete = true;
};

/// Everything an identification produced (written as a servotwin.axis-model/1 file by io).
struct AxisIdentification {
  std::string axis;
  double ts = 0.0;
  rapid::Solution solution;
  rapid::Bounds bounds;
  rapid::RegressorOptions regressors;
  /// Output-error refinement, when asked: its coefficients are the model in use (coefficients()).
  std::optional<rapid::Refinement> refinement;
  /// With a refinement: the solver's model's fit, before refinement (`fit` is the refined one's).
  std::optional<rapid::FitMetrics> solver_fit;
  std::optional<rapid::FitMetrics> fit;         ///< simulated tracking error on the identification data
  std::optional<rapid::FitMetrics> validation;  ///< on separate captures, when given
  /// With a refinement and validation captures: the solver's model on them, so that a user can see
  /// whether the refined model also predicts data it was not fitted on better (on the EMPS axis it
  /// does not: docs/rapid-identification-study.md).
  std::optional<rapid::FitMetrics> solver_validation;
  std::vector<ShiftTrial> shift_trials;         ///< when the shift was searched, every shift tried
  std::vector<std::string> sources;
  std::string length_unit = "mm";               ///< for people reading the file

  /// The model in use: the refined coefficients when refined, else the solver's.
  [[nodiscard]] const rapid::ModelCoefficients& coefficients() const noexcept {
    return refinement ? refinement->coefficients : solution.coefficients;
  }
};

/// Bounds with zero members replaced by the defaults of ts; validated.
rapid::Bounds complete_bounds(rapid::Bounds bounds, double ts);

/// Regression problem of one axis over several captures. Warnings of the regressor pass are
/// appended, prefixed by the capture's name. core::InputError naming the capture when the axis
/// is missing or the captures' sample periods differ.
rapid::RegressionProblem axis_problem(const std::vector<NamedCapture>& captures, const std::string& axis,
                                      const rapid::RegressorOptions& options, std::vector<std::string>& warnings);

/// Simulation-based tracking-error fit of a model on captures (all samples pooled); each capture
/// is simulated from its first measured position. give_up_above: as rapid::simulation_fit (the
/// shift search stops a candidate that can no longer be chosen).
rapid::FitMetrics simulated_fit(const rapid::AxisModel& model, const std::vector<NamedCapture>& captures,
                                const std::string& axis, int command_shift,
                                double give_up_above = std::numeric_limits<double>::infinity());

/// Names of the axes (in the first capture's order) whose command moves in at least one capture:
/// the axes an identification can say something about. A 3-axis capture of a one-axis program
/// holds two axes at rest.
std::vector<std::string> moving_axes(const std::vector<NamedCapture>& captures);

/// Output-error refinement (rapid/refine.hpp) of an identification on its identification
/// captures, with its shift: sets `refinement` and `solver_fit`, and `fit` to the refined model's
/// (identify_axis does this when settings.refine). A solver's model outside the bounds (Ls) is not
/// refined: a warning says so.
void refine_identification(AxisIdentification& identification, const std::vector<NamedCapture>& captures,
                           const rapid::RefineOptions& options = {});

/// The whole identification of one axis. With a shift search, core::InputError when the range is
/// inverted or wider than 64 samples.
AxisIdentification identify_axis(const std::vector<NamedCapture>& captures,
                                 const std::vector<NamedCapture>& validation, const std::string& axis,
                                 const IdentificationSettings& settings);

}  // namespace servotwin::vcnc
