#pragma once
/// \file
/// Prediction CSV (`servotwin predict -o`): `t`, per predicted axis `<axis>_cmd`, `<axis>_pred`,
/// `<axis>_err` (= cmd - pred, the predicted tracking error), then `contour_err` (signed, see
/// motion/contour.hpp) and `path` (line, arc, rapid or stop: what the commanded point is on).
/// With a measured capture: per axis `<axis>_meas`, `<axis>_meas_err` (the capture's own command
/// minus its position) and `contour_err_meas`, empty where the capture has no sample.

#include <iosfwd>

#include "servotwin/vcnc/prediction.hpp"

namespace servotwin::io {

/// Writes every sample with numbers that round-trip exactly. `measured` may be null.
void write_prediction_csv(std::ostream& out, const vcnc::Prediction& prediction,
                          const vcnc::MeasuredComparison* measured = nullptr);

}  // namespace servotwin::io
