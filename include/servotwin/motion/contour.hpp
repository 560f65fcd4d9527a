#pragma once
/// \file
/// Contour error: the distance from an actual (measured or predicted) point to the path the axes
/// were commanded to follow. Two references are offered:
///
/// * ContourPath: the program's lines and arcs exactly as the interpolator follows them (true
///   circles, helices and spirals; corners are the shared end points of two segments), with the
///   *progress* of the command along them at every sample: from servotwin's own plan, or from a
///   controller's recorded command matched to the program (any interpolation, blending and
///   override as they happened).
/// * CommandPolyline: the recorded command's own path, the polyline through its samples, when no
///   program is at hand.
///
/// **Which part of the path.** A path may pass the same place twice (a repeated circle, a
/// crossing diamond, the back-and-forth moves of an identification program, a rapid that crosses
/// the contour it leads to); the contour error at sample k is the distance to the nearest point of
/// the part of the path that is near the commanded point in both time and path length:
/// * run within [t_k - window, t_k + window] (default 0.2 s), and
/// * within 4 d_k of the commanded point's place along the path, d_k being the distance from the
///   actual point to the commanded point. The nearest point of the path lies within 2 d_k of the
///   commanded point in space (triangle inequality), and along a curve the path between them is
///   at most pi/2 times longer than their distance for up to a half circle: 4 d_k keeps it, and
///   keeps out another pass of the path that comes near the actual point only because the path
///   returns there (LinuxCNC measurements of a zig-zag after a rapid across it showed such a pass
///   0.12 mm away within 0.2 s).
/// The time-based query `ContourPath::nearest(p, t, window)` applies the window alone.

/// **Sign.** Positive to the left of the direction of travel, seen from the positive normal of
/// the segment's plane (G17: from +Z; G18: from +Y; G19: from +X) — the side of cutter
/// compensation G41. On a counter-clockwise (G03) circle in G17, positive is inside, on a
/// clockwise one outside. A deviation purely along the plane normal has no side: it counts as
/// positive.
///
/// **Joins.** Two rules keep the signed error continuous where segments meet:
/// * Only the part of each segment run within the window counts: a point near a join is compared
///   with the end of the segment before and the start of the one after, never with their far
///   parts (the far side of a full circle that ends where it began).
/// * When the nearest point is a corner (the end of one segment and the start of the next), the
///   side is seen from the sum of the two tangents there, the direction halfway through the turn.
///   A point past the corner (an overshoot) is then on the outside of the turn for both segments:
///   negative after a left (counter-clockwise) turn, positive after a right turn; at a reversal
///   (the sum is zero) it has no side and counts as positive.
/// * Past the path's open ends (before the first block, after the last) the path continues along
///   its end tangent: running past the end along the path is a positioning error, not a contour
///   deviation, and has no side.
/// Where the nearest point moves from one segment to the next, both give the same side, so the
/// signed error changes sign only where the distance passes zero (tested on the circle's rapid ->
/// arc -> rapid joins and the diamond's corners, lagging and overshooting).
///
#include <concepts>
#include <cstddef>
#include <optional>
#include <vector>

#include "servotwin/motion/interpolation.hpp"
#include "servotwin/motion/program.hpp"

namespace servotwin::motion {

/// Kind of path the commanded point is on at a time (for scoring per segment type). `Move`: the
/// command moves along a recorded path whose blocks are unknown (CommandPolyline).
enum class PathKind : unsigned char { Line, Arc, Rapid, Stop, Move };
inline constexpr std::size_t kPathKindCount = 5;
/// "line", "arc", "rapid", "stop", "move".
const char* path_kind_name(PathKind kind) noexcept;

/// Nearest point of the path to a given point.
struct ContourPoint {
  double distance = 0.0;         ///< Euclidean distance [mm]
  double signed_distance = 0.0;  ///< distance with the sign convention above
  Point nearest{};               ///< the nearest point of the path
  std::size_t segment = 0;       ///< index of the segment (polyline: chord) holding it
};

/// A path to measure contour errors against, sample by sample.
class ContourReference {
 public:
  virtual ~ContourReference() = default;
  /// Nearest point to p of the part of the path run within the window around sample k (clamped to
  /// the samples). core::InputError when p is not finite or the path has no motion.
  [[nodiscard]] virtual ContourPoint nearest(std::size_t k, const Point& p) const = 0;
  /// What the command is on at sample k.
  [[nodiscard]] virtual PathKind kind(std::size_t k) const noexcept = 0;
  /// Where the axes that the samples do not give stay.
  [[nodiscard]] virtual const Point& start_point() const noexcept = 0;
  /// Number of samples the reference covers.
  [[nodiscard]] virtual std::size_t sample_count() const noexcept = 0;
};

namespace detail {
struct ContourSegment;
}

/// How a recorded command is matched to a program (ContourPath::from_command).
struct CommandMatchOptions {
  double window_s = 0.2;  ///< contour-error window (see the file comment) [s]
  /// Largest distance the recorded command may keep from the programmed path [mm]: its blending
  /// and rounding. The match follows the command along the path within this much (and refuses
  /// nothing: CommandMatch says how far it was).
  double tolerance_mm = 0.01;
  /// Trace coordinates = program coordinates + offset [mm]; empty = found: zero, or else the
  /// offset that puts the program's end point on the command's last sample, whichever fits better.
  std::optional<Point> offset;
};

/// How well a recorded command followed a program.
struct CommandMatch {
  Point offset{};                ///< trace = program + offset [mm]
  double max_deviation = 0.0;    ///< largest distance of a command sample from the path [mm]
  std::size_t worst_sample = 0;  ///< where
  double rms_deviation = 0.0;    ///< RMS over the samples [mm]
  double progress_end = 0.0;     ///< path length the command covered [mm]
  double path_length = 0.0;      ///< length of the programmed path [mm]
  /// Largest commanded speed over the programmed feed on feed moves (lines, arcs): above 1 the
  /// controller ran faster than programmed (feed override). 0 without feed moves.
  double max_feed_ratio = 0.0;
  std::size_t feed_sample = 0;      ///< where
  std::size_t feed_line = 0;        ///< source line of that block
  double feed_mm_min = 0.0;         ///< its programmed feed
};

/// The commanded path of a program, for contour errors. Immutable; queries are allocation-free.
class ContourPath : public ContourReference {
 public:
  /// `plan` must be plan_motion(program, ...): its profile gives the progress at each sample.
  /// `window_s` is the window of the sample-based queries.
  ContourPath(const Program& program, const MotionPlan& plan, double window_s = 0.2);
  /// The program's path followed by a controller's recorded command: `command` (axes, positions,
  /// ts) is matched to the path sample by sample (monotone progress; see CommandMatchOptions).
  /// Axes the program moves must all be in `command`. core::InputError for a program without
  /// motion, a moved axis missing from the command, or non-finite samples.
  static ContourPath from_command(const Program& program, const Trajectory& command,
                                  const CommandMatchOptions& options = {});
  ~ContourPath() override;
  ContourPath(ContourPath&&) noexcept;
  ContourPath& operator=(ContourPath&&) noexcept;
  ContourPath(const ContourPath&) = delete;
  ContourPath& operator=(const ContourPath&) = delete;

  /// Motion segments (lines and arcs; dwells have none).
  [[nodiscard]] std::size_t segment_count() const noexcept;
  /// Nearest point of the part of the path run within [t - window, t + window] (t clamped to the
  /// samples; at least the point the command is on at t). core::InputError when there is no
  /// segment (a program without motion) or p is not finite.
  [[nodiscard]] ContourPoint nearest(const Point& p, double t, double window = 0.2) const;
  /// Kind of path the commanded point is on at time t: the running segment's block type, or Stop
  /// during dwells, exact stops between blocks and after the end.
  [[nodiscard]] PathKind kind_at(double t) const noexcept;
  /// Path length the command has covered at time t [mm] (interpolated between samples).
  [[nodiscard]] double progress_at(double t) const noexcept;
  /// How the recorded command matched (from_command); zero deviations for a plan.
  [[nodiscard]] const CommandMatch& match() const noexcept { return match_; }

  [[nodiscard]] ContourPoint nearest(std::size_t k, const Point& p) const override;
  [[nodiscard]] PathKind kind(std::size_t k) const noexcept override;
  /// Position before the first block (where axes the program does not move stay), in the
  /// trace's coordinates.
  [[nodiscard]] const Point& start_point() const noexcept override { return start_; }
  [[nodiscard]] std::size_t sample_count() const noexcept override { return progress_.size(); }

 private:
  ContourPath() = default;
  [[nodiscard]] ContourPoint nearest_in(const Point& p, double s_lo, double s_hi) const;
  /// +1 / -1: the side of p seen from the nearest point q at parameter s of segment i, whose
  /// tangent there is `tangent` (a corner: from both segments' tangents).
  [[nodiscard]] double corner_side(std::size_t i, double s, const Point& tangent, const Point& q,
                                   const Point& p) const noexcept;

  std::vector<detail::ContourSegment> segments_;
  std::vector<double> progress_;  ///< path position of the command at each sample [mm]
  std::vector<PathKind> kinds_;   ///< per sample (from_command); empty: from the segments' times
  double ts_ = 0.0;
  double window_s_ = 0.2;
  double duration_ = 0.0;
  Point start_{};
  Point offset_{};
  CommandMatch match_;
};

/// The recorded command's own path: the polyline through its samples. Sign: seen from +Z when the
/// samples include X and Y (else from the axis they lack, +Y for X-Z, +X for Y-Z); a single axis
/// has no side (positive). Queries are allocation-free.
class CommandPolyline : public ContourReference {
 public:
  /// `command` must have at least one axis and two samples; window as ContourPath's.
  explicit CommandPolyline(const Trajectory& command, double window_s = 0.2);

  [[nodiscard]] ContourPoint nearest(std::size_t k, const Point& p) const override;
  /// Stop where the command does not move, Move elsewhere.
  [[nodiscard]] PathKind kind(std::size_t k) const noexcept override;
  [[nodiscard]] const Point& start_point() const noexcept override { return start_; }
  [[nodiscard]] std::size_t sample_count() const noexcept override { return points_.size(); }

 private:
  std::vector<Point> points_;
  std::vector<double> arc_;           ///< path length from the first sample
  std::vector<double> block_radius_;  ///< per block of kBlock chords: bounding radius around its first point
  std::size_t window_ = 0;            ///< samples each side
  std::size_t normal_ = 2;
  bool has_side_ = true;
  Point start_{};
};

/// Contour errors of sampled actual positions: `actual[i][k]` is axis `axes[i]` at sample k;
/// axes not listed stay at the reference's start point. One signed error per sample. The samples
/// are shared among `workers` threads (0: every core; core/parallel.hpp), with the same result for
/// any number.
std::vector<double> contour_errors(const ContourReference& path, const std::vector<Axis>& axes,
                                   const std::vector<std::vector<double>>& actual, std::size_t workers = 0);

/// The former time-based form, contour_errors(path, axes, actual, ts[, window]), now
/// contour_errors_in_window: deleted so that such a call does not compile as workers = ts.
template <std::floating_point Seconds>
std::vector<double> contour_errors(const ContourReference& path, const std::vector<Axis>& axes,
                                   const std::vector<std::vector<double>>& actual, Seconds ts,
                                   double window = 0.2) = delete;

/// Same for a ContourPath queried by time t = k ts with the given window (kept for callers of the
/// time-based interface; one thread).
std::vector<double> contour_errors_in_window(const ContourPath& path, const std::vector<Axis>& axes,
                                             const std::vector<std::vector<double>>& actual, double ts,
                                             double window = 0.2);

}  // namespace servotwin::motion
