#pragma once
/// \file
/// Shaping a multi-axis toolpath command and measuring the path deviation it causes.
///
/// An input shaper filters every axis of the commanded trajectory with the same pulse train, so a
/// straight move stays on its line (the shaped point is a weighted average of commanded points of
/// that line) but corners are rounded and arcs shrink: the shaped point at sample k is
/// Σ A_i p[k - d_i], inside the convex hull of the commanded points of the last max_delay samples.
/// The **contour distortion** is the distance from each shaped point to the commanded path, here
/// the polyline through the commanded samples (chords of arcs: at 1 ms sampling a chord lies within
/// v² ts² / (8 R) of the true arc, well below the distortions of interest).
///
/// **Which part of the path.** Like motion::ContourPath, the distance is taken to the part of the
/// path commanded around that time, not to an unrelated pass of a path that revisits a place: the
/// segments between samples k - max_delay - margin and k + margin (default margin = max_delay + 1).
/// For positive amplitudes this always contains the nearest point of the window's convex hull's
/// generators, so on a path that does not come back within the window the result equals the
/// distance to the whole polyline.
///
/// The module map keeps shaping independent of motion: trajectories are passed as columns
/// (`positions[i][k]`, axis i at sample k, the layout of motion::Trajectory::positions).

#include <cstddef>
#include <optional>
#include <vector>

#include "servotwin/shaping/discretization.hpp"

namespace servotwin::shaping {

/// Columns of positions sampled at a common period: columns[i][k] is axis i at sample k.
using Columns = std::vector<std::vector<double>>;

/// Shapes every column with a RealtimeShaper whose history starts at the column's first value, and
/// continues max_delay() samples past the end with the last value held, so the shaped command
/// reaches the end point: every output column has n + shaper.max_delay() samples. Throws
/// core::InputError (field "positions") for no columns, columns of different or zero length, or
/// non-finite values.
Columns shape_columns(const Columns& positions, const DiscreteShaper& shaper);

/// Distances from shaped points to the commanded polyline.
struct PathDeviation {
  std::vector<double> distance;  ///< per shaped sample [length unit of the positions]
  double rms = 0.0;              ///< root mean square of `distance`
  double max = 0.0;              ///< largest distance
  std::size_t max_index = 0;     ///< sample of the largest distance (time = max_index * ts)
  std::vector<double> max_point; ///< the shaped point there, one value per axis
  std::size_t max_segment = 0;   ///< commanded segment [max_segment, max_segment + 1] nearest to it
};

/// Distance of every `shaped` sample k to the polyline of `commanded`, restricted to the segments
/// between samples k - max_delay - margin and k + margin (clamped to the path; `margin` defaults
/// to max_delay + 1). Commanded samples past the end are the end point held. Throws
/// core::InputError (field "positions") when the axis counts differ, a column is empty or lengths
/// differ within a trajectory.
PathDeviation path_deviation(const Columns& commanded, const Columns& shaped, std::size_t max_delay,
                             std::optional<std::size_t> margin = std::nullopt);

}  // namespace servotwin::shaping
