#pragma once
// Human-readable summary of a prediction and, when measured, its scores (`predict`, `demo`).
#include "servotwin/vcnc/prediction.hpp"

namespace servotwin::cli {

/// Predicted tracking error per axis and contour error (RMS and max, overall and per kind of path).
void print_prediction_summary(const vcnc::Prediction& prediction);
/// Alignment and the table of scores (measured vs predicted RMS, max difference, NRMSE).
void print_comparison(const vcnc::MeasuredComparison& comparison, double ts);

}  // namespace servotwin::cli
