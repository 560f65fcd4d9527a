#pragma once
/// \file
/// Interpolation: program blocks -> commanded position of each axis sampled at ts.
///
/// The path is followed exactly (lines, true circles, helices). The feed along the path has an
/// acceleration limit (trapezoidal velocity, the thesis's setting for identification) and an
/// optional jerk limit (S-curve). The planner stops exactly where the path turns sharper than
/// `corner_angle_deg`, keeps the feed through tangent transitions, and limits the speed through
/// shallow corners and curvature jumps so that the sampled trajectory never exceeds the limits
/// when checked by finite differences. Every exact stop falls on a sample: the profile between
/// two stops is slowed down by less than one sample so its duration is a whole number of samples.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

struct InterpolationLimits {
  double ts = 0.001;                 ///< sample period [s]
  double accel = 2000.0;             ///< acceleration limit along the path [mm/s^2]
  std::optional<double> jerk;        ///< jerk limit [mm/s^3]; empty = trapezoidal profile
  double rapid_feed_mm_min = 15000;  ///< feed of rapid moves [mm/min]
  double max_feed_mm_min = 1e9;      ///< cap on programmed feeds [mm/min]
  double corner_angle_deg = 1.0;     ///< exact stop when the direction changes more than this
  /// On arcs, the share of `accel` available along the path; the rest, sqrt(1 - r^2) * accel,
  /// bounds the centripetal acceleration, so the total stays within `accel`.
  double arc_tangential_ratio = 0.5;
};

/// Commanded trajectory sampled at ts from t = 0.
struct Trajectory {
  double ts = 0.0;
  std::vector<Axis> axes;                      ///< axes of the columns, in X, Y, Z order
  std::vector<std::vector<double>> positions;  ///< positions[i][k]: axis i at sample k [mm]
  [[nodiscard]] std::size_t size() const noexcept { return positions.empty() ? 0 : positions.front().size(); }
};

/// A planned program: segments with their feed profiles, ready to be sampled.
class MotionPlan;

/// Plans the feed profile of a program. Throws core::InputError for invalid limits (ts, accel,
/// jerk <= 0) or zero/negative programmed feeds.
MotionPlan plan_motion(const Program& program, const InterpolationLimits& limits);

/// Samples a plan for the given axes (all axes the program uses when `axes` is empty).
Trajectory sample(const MotionPlan& plan, const std::vector<Axis>& axes = {});

/// plan_motion + sample.
Trajectory interpolate(const Program& program, const InterpolationLimits& limits,
                       const std::vector<Axis>& axes = {});

}  // namespace servotwin::motion
