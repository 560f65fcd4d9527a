#pragma once
// Human-readable summary of a prediction and, when measured, its scores (`predict`, `demo`).
#include "servotwin/vcnc/prediction.hpp"

namespace servotwin::cli {

/// The prediction's warnings (stderr) and notes, predicted tracking error per axis and contour
/// error (RMS and max, overall and per kind of path).
void print_prediction_summary(const vcnc::Prediction& prediction);
/// Alignment (a capture aligned to the program, or `from_trace`: the trace the prediction was
/// driven by) and the table of scores (measured vs predicted RMS, max difference, NRMSE).
void print_comparison(const vcnc::MeasuredComparison& comparison, double ts, bool from_trace = false);

}  // namespace servotwin::cli
