#pragma once
/// \file
/// Prediction (thesis sections 3.4 and 4.3): identified axis models follow a part program before
/// anything is cut. The program is interpolated, each axis model is simulated on its commanded
/// trajectory, and the tracking errors and the contour error (motion/contour.hpp: the true
/// distance to the commanded path, positive to the left of travel) come out per sample. A measured
/// capture of the same program can be aligned in time and scored against the prediction.

#include <cstddef>
#include <memory>
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
};

/// Commanded and predicted motion of the program's axes, sampled at the models' period.
struct Prediction {
  double ts = 0.0;
  std::vector<motion::Axis> axes;                   ///< axes with a model that the program moves, X, Y, Z order
  std::vector<std::vector<double>> command;         ///< command[i][k]: axis axes[i] at t = k ts [mm]
  std::vector<std::vector<double>> predicted;       ///< predicted actual position
  std::vector<double> contour_error;                ///< of the predicted motion [mm], signed
  std::vector<motion::PathKind> kind;               ///< what the commanded point is on at each sample
  std::shared_ptr<const motion::ContourPath> path;  ///< the commanded path (for measured comparisons)
  double contour_window_s = 0.2;
  [[nodiscard]] std::size_t size() const noexcept { return kind.size(); }
  /// Predicted tracking error command - predicted of axis i at sample k.
  [[nodiscard]] double tracking_error(std::size_t i, std::size_t k) const noexcept {
    return command[i][k] - predicted[i][k];
  }
};

/// Interpolates `program` with `limits` (its ts is replaced by the models' common period) and
/// simulates every model whose axis the program moves, each from rest at its start position.
/// core::InputError naming the model's source or the program when: no model is given, an axis
/// name is not x, y or z or appears twice, the models' sample periods differ, or the program
/// moves an axis without a model.
Prediction predict(const motion::Program& program, const std::string& program_name, motion::InterpolationLimits limits,
                   const std::vector<AxisModelSpec>& models, const PredictionOptions& options = {});

/// Predicted vs measured scores of one quantity over the samples of one kind of path.
struct PredictionScore {
  std::string quantity;  ///< "x tracking", "y tracking", ..., "contour"
  std::string kind;      ///< "all", "line", "arc", "rapid", "stop"
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

}  // namespace servotwin::vcnc
