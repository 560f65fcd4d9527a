#pragma once
/// \file
/// Contour error: the distance from an actual (measured or predicted) point to the commanded
/// path, the path being the program's lines and arcs exactly as the interpolator follows them
/// (true circles, helices and spirals; corners are the shared end points of two segments).
///
/// **Which part of the path.** A path may pass the same place twice (a repeated circle, a
/// crossing diamond); the contour error at time t is the distance to the nearest point of the
/// segments that the commanded motion runs on within [t - window, t + window] (default 0.2 s),
/// i.e. to the part of the path the axis is following, not to an unrelated pass.
///
/// **Sign.** Positive to the left of the direction of travel, seen from the positive normal of
/// the segment's plane (G17: from +Z; G18: from +Y; G19: from +X) — the side of cutter
/// compensation G41. On a counter-clockwise (G03) circle in G17, positive is inside, on a
/// clockwise one outside. A deviation purely along the plane normal, and the distance to a
/// corner point in the direction of a segment's axis, have no side: they count as positive.

#include <cstddef>
#include <vector>

#include "servotwin/motion/interpolation.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

/// Kind of path the commanded point is on at a time (for scoring per segment type).
enum class PathKind : unsigned char { Line, Arc, Rapid, Stop };
/// "line", "arc", "rapid", "stop".
const char* path_kind_name(PathKind kind) noexcept;

/// Nearest point of the path to a given point.
struct ContourPoint {
  double distance = 0.0;         ///< Euclidean distance [mm]
  double signed_distance = 0.0;  ///< distance with the sign convention above
  Point nearest{};               ///< the nearest point of the path
  std::size_t segment = 0;       ///< index of the segment holding it
};

namespace detail {
struct ContourSegment;
}

/// The commanded path of a planned program, for contour errors. Immutable; queries are
/// allocation-free.
class ContourPath {
 public:
  /// `plan` must be plan_motion(program, ...): its moves give each segment's time span.
  ContourPath(const Program& program, const MotionPlan& plan);
  ~ContourPath();
  ContourPath(ContourPath&&) noexcept;
  ContourPath& operator=(ContourPath&&) noexcept;
  ContourPath(const ContourPath&) = delete;
  ContourPath& operator=(const ContourPath&) = delete;

  /// Motion segments (lines and arcs; dwells have none).
  [[nodiscard]] std::size_t segment_count() const noexcept;
  /// Nearest point of the segments run within [t - window, t + window] (at least the segment
  /// running at t, clamped to the program's duration). core::InputError when there is no segment
  /// (a program without motion) or p is not finite.
  [[nodiscard]] ContourPoint nearest(const Point& p, double t, double window = 0.2) const;
  /// Kind of path the commanded point is on at time t: the running segment's block type, or Stop
  /// during dwells, exact stops between blocks and after the end.
  [[nodiscard]] PathKind kind_at(double t) const noexcept;
  /// Position before the first block (where axes the program does not move stay).
  [[nodiscard]] const Point& start_point() const noexcept { return start_; }

 private:
  std::vector<detail::ContourSegment> segments_;
  double duration_ = 0.0;
  Point start_{};
};

/// Contour errors of sampled actual positions: `actual[i][k]` is axis `axes[i]` at t = k ts;
/// axes not listed stay at the program's start position. One signed error per sample.
std::vector<double> contour_errors(const ContourPath& path, const std::vector<Axis>& axes,
                                   const std::vector<std::vector<double>>& actual, double ts, double window = 0.2);

}  // namespace servotwin::motion
