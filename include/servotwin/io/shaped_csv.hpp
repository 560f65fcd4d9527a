#pragma once
/// \file
/// The shaped-trajectory CSV written by `servotwin shaper apply`:
///
///   t,x_cmd,y_cmd,...,x_shaped,y_shaped,...,deviation
///
/// one row per sample at t = t0 + k·ts. The shaped command is longer than the commanded one by the
/// shaper's duration; past the end of the command the `_cmd` columns hold the end point while the
/// shaped command settles. `deviation` is the distance of the shaped point from the commanded path
/// (shaping::path_deviation), in the trajectory's length unit.
#include <ostream>
#include <string>
#include <vector>

namespace servotwin::io {

/// What write_shaped_csv writes; all shaped columns and `deviation` have the same length, at least
/// as long as every commanded column (the commanded columns are non-empty).
struct ShapedTrajectory {
  double t0 = 0.0;                                 ///< time of the first sample [s]
  double ts = 0.0;                                 ///< sample period [s]
  std::vector<std::string> axes;                   ///< axis names as in the input ("x", "y", ...)
  std::vector<std::vector<double>> commanded;      ///< one column per axis
  std::vector<std::vector<double>> shaped;         ///< one column per axis
  std::vector<double> deviation;                   ///< distance to the commanded path per sample
};

/// Writes the CSV above, streaming in 64 KiB chunks, times printed at the decimals of t0 and ts.
void write_shaped_csv(std::ostream& out, const ShapedTrajectory& trajectory);

}  // namespace servotwin::io
