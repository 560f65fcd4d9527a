#pragma once
/// \file
/// Prediction (thesis sections 3.4 and 4.3): identified axis models follow a part program before
/// anything is cut. The program is interpolated, each axis model is simulated on its commanded
/// trajectory, and the tracking errors and the contour error (motion/contour.hpp: the true
/// distance to the commanded path, positive to the left of travel) come out per sample. A measured
/// capture of the same program can be aligned in time and scored against the prediction.
///
/// A real controller's look-ahead, corner blending, jerk limits and feed override never match
/// servotwin's interpolator; the thesis (section 4.3.3) drove its models with the captured
/// command. predict_from_command does that: the commanded trajectory is a trace's `<axis>_cmd`
/// columns, the contour error is measured against the program's path (the command matched to it
/// sample by sample) or, without a program, against the command's own path, and the trace's
/// `<axis>_act` columns are scored beside the prediction.

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/core/capture.hpp"
#include "servotwin/motion/contour.hpp"
#include "servotwin/motion/interpolation.hpp"
#include "servotwin/motion/program.hpp"
#include "servotwin/rapid/axis_model.hpp"

namespace servotwin::vcnc {

/// One identified axis: its name (x, y or z), model and the command shift it was identified with.
struct AxisModelSpec {
  std::string axis;
  rapid::AxisModel model;
  int command_shift = 0;
  std::string source;  ///< where it came from (file name), for messages
};

struct PredictionOptions {
  /// Contour error: the path near the commanded point, [t - window, t + window] [s].
  double contour_window_s = 0.2;
  /// Threads the work is shared among (0: every core; the result is the same for any number): the
  /// interpolation beside the contour path and the samples' path kinds, then the axes' models,
  /// then the contour errors.
  std::size_t workers = 0;
};

/// Commanded and predicted motion of the program's axes, sampled at the models' period.
struct Prediction {
  double ts = 0.0;
  std::vector<motion::Axis> axes;                   ///< axes with a model that the program moves, X, Y, Z order
  std::vector<std::vector<double>> command;         ///< command[i][k]: axis axes[i] at t = k ts [mm]
  std::vector<std::vector<double>> predicted;       ///< predicted actual position
  std::vector<double> contour_error;                ///< of the predicted motion [mm], signed
  std::vector<motion::PathKind> kind;               ///< what the commanded point is on at each sample
  /// The path contour errors are measured against (for measured comparisons and reports).
  std::shared_ptr<const motion::ContourReference> path;
  double contour_window_s = 0.2;
  /// What the prediction rests on that a user should know (e.g. a program that states no
  /// path-control mode); `notes` are facts (e.g. the offset of a trace from the program).
  std::vector<std::string> warnings, notes;
  /// Axes whose model is unstable (rapid::AxisModel::is_stable): their prediction diverges; a
  /// warning says so, and the prediction CSV and report carry it.
  std::vector<motion::Axis> unstable;
  [[nodiscard]] std::size_t size() const noexcept { return kind.size(); }
  /// Predicted tracking error command - predicted of axis i at sample k.
  [[nodiscard]] double tracking_error(std::size_t i, std::size_t k) const noexcept {
    return command[i][k] - predicted[i][k];
  }
};

/// Interpolates `program` with `limits` (its ts is replaced by the models' common period) and
/// simulates every model whose axis the program moves, each from rest at its start position.
/// The program's path-control modes are honoured by the planner (motion/interpolation.hpp); a
/// program that states none gets a warning (the corner rule of `limits` decides, not the
/// controller's default), one that blends a note (servotwin's planner does not round corners the
/// controller's way: predict from its recorded command instead).
/// core::InputError naming the model's source or the program when: no model is given, an axis
/// name is not x, y or z or appears twice, the models' sample periods differ, or the program
/// moves an axis without a model.
Prediction predict(const motion::Program& program, const std::string& program_name, motion::InterpolationLimits limits,
                   const std::vector<AxisModelSpec>& models, const PredictionOptions& options = {});

/// How predict_from_command reads a trace.
struct CommandPredictionOptions {
  double contour_window_s = 0.2;  ///< see PredictionOptions
  std::size_t workers = 0;        ///< see PredictionOptions
  /// Largest distance the trace's command may keep from the program's path [mm]; empty = from the
  /// program's path-control modes: 0.01 mm plus 1e-4 of the motion range for exact stop and exact
  /// path, the largest stated blend tolerance plus that for blending with a tolerance, and 10 % of
  /// the motion range where blending has no tolerance or the mode is not stated.
  std::optional<double> path_tolerance_mm;
  /// Trace coordinates = program coordinates + offset [mm]; empty = found (motion/contour.hpp).
  std::optional<motion::Point> offset;
};

/// Predicts from a controller's recorded command: every model is simulated on the trace's
/// `<axis>_cmd` column (with its command shift, from rest at the first command). With `program`,
/// contour errors are measured against its lines and arcs, the trace matched to it in time (the
/// command's progress along the path) and space (offset); without, against the command's own
/// path. core::InputError naming the trace or a model's source when: no model is given, a model's
/// axis is missing from the trace, the models' sample periods differ from each other or from the
/// trace's, an axis that moves (in the program, or in the trace without one) has no model, the
/// command leaves the program's path by more than the tolerance (not a run of this program), or
/// it covers less than half of the program's path.
Prediction predict_from_command(const core::Capture& trace, const std::string& trace_name, const motion::Program* program,
                                const std::string& program_name, const std::vector<AxisModelSpec>& models,
                                const CommandPredictionOptions& options = {});

/// Predicted vs measured scores of one quantity over the samples of one kind of path.
struct PredictionScore {
  std::string quantity;  ///< "x tracking", "y tracking", ..., "contour"
  std::string kind;      ///< "all", "line", "arc", "rapid", "stop", "move"
  rapid::FitMetrics metrics;
};

/// A measured capture of the predicted program, aligned to the prediction's samples.
struct MeasuredComparison {
  /// Capture sample that matches prediction sample 0 (may be negative when the capture starts late).
  std::ptrdiff_t offset = 0;
  std::size_t first = 0, count = 0;           ///< prediction samples [first, first + count) have a measurement
  double command_mismatch_rms = 0.0;          ///< RMS of capture command - interpolated command after alignment [mm]
  std::vector<std::vector<double>> actual;    ///< measured position per predicted axis, NaN without measurement
  std::vector<std::vector<double>> tracking_error;  ///< the capture's command - position, NaN without measurement
  std::vector<double> contour_error;          ///< of the measured motion, NaN without measurement
  std::vector<PredictionScore> scores;        ///< per quantity: "all" first, then each kind with >= 10 samples
};

/// Aligns `capture` to the prediction by its commanded positions (start of motion, refined by
/// least squares over +-50 samples) and scores tracking and contour errors. core::InputError
/// naming `source` when the sample periods differ, a predicted axis is missing, the aligned
/// commands differ by more than 1e-3 of the motion range (not a capture of this program), or
/// fewer than half of the prediction's samples are covered.
MeasuredComparison compare_with_capture(const Prediction& prediction, const core::Capture& capture,
                                        const std::string& source);

/// Scores a prediction made by predict_from_command(trace, ...) against the same trace's `<axis>_act`
/// columns, sample by sample (no alignment: the prediction runs on the trace's own samples).
/// core::InputError naming `source` when the trace has another length or lacks a predicted axis.
MeasuredComparison compare_with_trace(const Prediction& prediction, const core::Capture& trace, const std::string& source);

}  // namespace servotwin::vcnc
