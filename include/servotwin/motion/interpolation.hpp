#pragma once
/// \file
/// Interpolation: program blocks -> commanded position of each axis sampled at ts.
///
/// **Geometry.** Linear and rapid blocks are straight lines. Arcs are true circles in the block's
/// plane (G17 XY seen from +Z, G18 ZX seen from +Y, G19 YZ seen from +X; ArcCcw turns the
/// positive way in the (first, second) plane axes of that list), helical when the coordinate
/// along the plane normal changes, a full turn when the start equals the end in the plane. When
/// the programmed start and end radii differ (readers accept small differences), the radius
/// changes linearly with the angle (a spiral, as LinuxCNC does) so that the end point is still
/// reached; its path parameter is then the angle times the largest |dp/dangle|, so the true speed
/// never exceeds the planned one. Zero-length moves and `None` blocks are skipped; a dwell holds
/// the position for ceil(dwell / ts) samples.
///
/// **Feeds.** Rapid blocks run at `rapid_feed_mm_min`, linear blocks and arcs at
/// min(programmed feed, `max_feed_mm_min`).
///
/// **Limits along the path.** Path speed <= feed; the magnitude of the acceleration VECTOR <=
/// `accel` everywhere; with `jerk`, the magnitude of the jerk vector <= `jerk`. On lines the
/// tangential acceleration (jerk) may use the whole limit. On arcs (curvature bound k2 =
/// max|p''(s)|, k3 = max|p'''(s)|, r = `arc_tangential_ratio`) the tangential acceleration is
/// limited to r accel and the speed to sqrt(c accel / k2), with c = sqrt(1 - r^2) for circles and
/// helices (tangential and centripetal parts are orthogonal; LinuxCNC uses the same split) and
/// slightly less for spirals (their small cross term is included); with jerk, the tangential jerk
/// is limited to r jerk and the speed v so that k3 v^3 + 3 k2 v (r accel) <= (1 - r) jerk: the
/// jerk vector of a path with speed v is p''' v^3 + 3 p'' v a_t + p' j_t, whose first term is the
/// rotation of the centripetal vector (v^3 / R^2 on a circle) and whose second is the cross term
/// of a changing speed on a curve.
///
/// **Junctions.** theta = angle between the end tangent of one segment and the start tangent of
/// the next. The path-control mode of the first block (Block::path_control) decides: ExactStop
/// (G61) -> exact stop; ExactPath (LinuxCNC G61) -> exact stop unless theta <= 1e-9 rad (tangent
/// and collinear joins run on); Blend (G64) and Unstated -> exact stop when theta >
/// `corner_angle_deg` (and > 1e-9 rad, so numerically tangent joins never stop). Blending does not
/// round corners: a blended corner is passed on the programmed path at a capped speed (below). Otherwise the feed continues through the junction, and the speed there is
/// limited so that the sampled trajectory still respects the limits when checked by finite
/// differences: a junction where the velocity vector jumps by v |p'_2 - p'_1| (a shallow corner)
/// adds up to v |p'_2 - p'_1| / ts to a second difference / ts^2 and v |p'_2 - p'_1| / ts^2 to a
/// third difference / ts^3; with a jerk limit, a jump of the curvature vector (line -> arc, arcs
/// of different radius; the tangential acceleration is zero at junctions in S-curve mode) adds
/// (3/4) v^2 |p''_2 - p''_1| / ts to a third difference / ts^3. All junctions whose jumps can fall
/// into one finite-difference window (2 ts, with jerk 3 ts) are summed, and their total is kept
/// within `junction_share` of the limit: a junction's speed is capped when needed. The motion
/// that can fall into the same window as the junction (a "zone" of path length
/// w (v + w accel) around it, w the window) is planned with the limits reduced by the share the
/// junctions actually use, so that jumps plus regular motion never exceed the limit. Junctions
/// whose jumps are at rounding level (|p'_2 - p'_1| <= 16 eps, |p''_2 - p''_1| <= 16 eps |p''|:
/// collinear lines, an arc continuing on the same circle) are smooth: no cap, no zone, and between
/// equal limits the profile simply continues through them (also in S-curve mode). Program start
/// and end and dwells are exact stops; `exact_stop_every_block` (a controller without look-ahead)
/// makes every block end in one, whatever the program states.
/// The bound adds the magnitudes of the jumps (it does not count on their cancelling), so dense
/// polylines (many chords per window) are planned conservatively: chords of a circle of radius R
/// run at about sqrt(junction_share accel R / 2) without a jerk limit (half the true circle's
/// speed) and much slower with one, where every kink adds v |p'_2 - p'_1| / ts^2 to the third
/// difference. Program curved contours as arcs.
///
/// **Profiles.** The path is split into pieces with constant limits (blocks, and the junction
/// zones); pieces joined by smooth junctions with equal limits form one profile unit.
/// Trapezoidal (no jerk): forward/backward pass over the unit boundary speeds, then per unit
/// accelerate / cruise / decelerate: time optimal for piecewise-constant limits. Jerk-limited:
/// every unit starts and ends with zero acceleration and uses a 7-phase S-curve between its end
/// speeds; the forward/backward pass uses the jerk-limited distance needed to change speed: the
/// exact minimum time for a single rest-to-rest move.
///
/// **Sampling** walks spans and phases in order (no search per sample) and appends to columns
/// reserved up front. On arcs, cos/sin of the angle come from libm at a reference angle that is
/// refreshed whenever the angle moves more than 0.125 rad away, and short Taylor polynomials of
/// the offset (truncation < 1.2e-18) through the angle-addition formulas: no error accumulates
/// and positions stay within ~1e-15 R of the true circle.
///
/// **Exact stops on samples.** The profile of each chain between two exact stops is slowed down
/// by a factor k >= 1 (speed / k, acceleration / k^2, jerk / k^3, so all limits still hold) so that
/// its duration is a whole number of samples, i.e. less than one sample longer than the optimum.
/// Every exact-stop point is then a sample and equals the programmed end point bit for bit.
/// Continuous-feed junctions are passed between samples; `MotionPlan::position_at` evaluates the
/// continuous profile (it passes through them).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

/// Interpolator settings. Invalid values make plan_motion throw core::InputError naming the
/// field ("accel", "jerk", ...).
struct InterpolationLimits {
  double ts = 0.001;                 ///< sample period [s], > 0
  double accel = 2000.0;             ///< acceleration limit (vector magnitude) [mm/s^2], > 0
  std::optional<double> jerk;        ///< jerk limit [mm/s^3], > 0; empty = trapezoidal profile
  double rapid_feed_mm_min = 15000;  ///< feed of rapid moves [mm/min], > 0
  double max_feed_mm_min = 1e9;      ///< cap on programmed feeds [mm/min], > 0
  double corner_angle_deg = 1.0;     ///< exact stop when the direction changes more than this, [0, 180]
  /// Exact stop at the end of every motion block, whatever mode the program states (a simple
  /// controller without look-ahead), instead of continuous feed through shallow and tangent junctions.
  bool exact_stop_every_block = false;
  /// On arcs, the share of `accel` (and `jerk`) available along the path; the rest bounds the
  /// centripetal acceleration, so the total stays within `accel`. In (0, 1).
  double arc_tangential_ratio = 0.5;
  /// Largest share of `accel` (and `jerk`) that the velocity (and curvature) jumps of the
  /// continuous-feed junctions inside one finite-difference window may use. In (0, 1).
  double junction_share = 0.5;
  /// Guard against absurd programs: plan_motion throws core::InputError when the trajectory
  /// would have more samples than this (1e8 samples = 27.8 h at 1 ms, 2.4 GB for three axes).
  std::size_t max_samples = 100'000'000;
};

/// Commanded trajectory sampled at ts from t = 0.
struct Trajectory {
  double ts = 0.0;
  std::vector<Axis> axes;                      ///< axes of the columns, in X, Y, Z order
  std::vector<std::vector<double>> positions;  ///< positions[i][k]: axis i at sample k [mm]
  [[nodiscard]] std::size_t size() const noexcept { return positions.empty() ? 0 : positions.front().size(); }
};

/// Timing of one block that takes time (motion or dwell) in a plan.
struct PlannedMove {
  std::size_t block = 0;       ///< index in Program::blocks
  std::size_t line = 0;        ///< source line of the block
  BlockType type = BlockType::None;
  double length = 0.0;         ///< path length [mm] (spirals: the path parameter, >= true length)
  double feed = 0.0;           ///< speed limit of the block [mm/s] (rapid feed or capped programmed feed)
  double t_start = 0.0;        ///< time the block starts [s]
  double t_end = 0.0;          ///< time the block ends [s]
  double v_start = 0.0;        ///< path speed at the start [mm/s]
  double v_end = 0.0;          ///< path speed at the end [mm/s]
  bool stop_at_end = false;    ///< the block ends with an exact stop (then t_end is a sample time)
};

namespace detail {
struct PlanData;
}

/// A planned program: segments with their feed profiles, ready to be sampled. Cheap to copy
/// (shares its immutable data).
class MotionPlan {
 public:
  /// An empty plan (no motion, one sample at the origin).
  MotionPlan();
  explicit MotionPlan(std::shared_ptr<const detail::PlanData> data);

  [[nodiscard]] const InterpolationLimits& limits() const noexcept;
  [[nodiscard]] double ts() const noexcept;
  /// Number of samples of the trajectory (the first at t = 0, the last at the end point).
  [[nodiscard]] std::size_t sample_count() const noexcept;
  /// Duration [s] = (sample_count() - 1) * ts.
  [[nodiscard]] double duration() const noexcept;
  /// Mask of the axes the program uses (Program::used_axes()).
  [[nodiscard]] std::uint8_t used_axes() const noexcept;
  /// Position at t = 0 and after the last block.
  [[nodiscard]] Point start_point() const noexcept;
  [[nodiscard]] Point end_point() const noexcept;
  /// Blocks that take time, in program order.
  [[nodiscard]] const std::vector<PlannedMove>& moves() const noexcept;
  /// Position of the continuous (time-scaled) profile at time t [s]; clamps t to [0, duration()].
  /// For diagnostics and tests: sample() is the fast way to get the whole trajectory.
  [[nodiscard]] Point position_at(double t) const;
  /// Path speed of the continuous profile at time t [s] (0 during dwells and exact stops).
  [[nodiscard]] double speed_at(double t) const;

  [[nodiscard]] const detail::PlanData& data() const noexcept { return *data_; }

 private:
  std::shared_ptr<const detail::PlanData> data_;
};

/// Plans the feed profile of a program. Throws core::InputError for invalid limits, zero or
/// negative programmed feeds, non-finite coordinates, negative dwells, arcs whose start or end
/// lies on the centre, blocks that do not start where the previous one ended, and programs
/// that would need more than `limits.max_samples` samples.
MotionPlan plan_motion(const Program& program, const InterpolationLimits& limits);

/// Samples a plan for the given axes (when `axes` is empty: all axes the program uses, including
/// both axes of the plane of every arc; X when it uses none). Columns come in X, Y, Z order.
/// Throws core::InputError for repeated axes.
Trajectory sample(const MotionPlan& plan, const std::vector<Axis>& axes = {});

/// Like sample(), but into an existing trajectory whose column memory is reused: no allocation
/// when the columns' capacity suffices (e.g. when sampling many plans in a loop).
void sample_into(const MotionPlan& plan, Trajectory& out, const std::vector<Axis>& axes = {});

/// plan_motion + sample.
Trajectory interpolate(const Program& program, const InterpolationLimits& limits,
                       const std::vector<Axis>& axes = {});

}  // namespace servotwin::motion
