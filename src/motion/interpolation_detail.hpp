#pragma once
// Internal data and steps of the interpolator (not installed). The steps are, in order:
// geometry (blocks -> segments), junctions (exact stops, junction speed caps, zones -> pieces),
// profiles (forward/backward pass, phases, time scaling onto samples) and sampling.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "servotwin/motion/interpolation.hpp"

namespace servotwin::motion::detail {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// Path of one motion block, parametrised by the path parameter s in [0, length] with
/// |dp/ds| <= 1 (= 1 except on spirals).
struct Geometry {
  bool is_arc = false;
  Point start{};
  Point end{};
  double length = 0.0;
  // Line: p(s) = start + s * dir.
  Point dir{};
  // Arc: phi = s * rad_per_s, a = angle0 + sense * phi, r = r0 + dr * phi,
  // p = base + r (cos a e1 + sin a e2) + phi * rise.
  Point base{};
  Point e1{};
  Point e2{};
  Point rise{};
  double angle0 = 0.0;
  double sense = 1.0;
  double r0 = 0.0;
  double dr = 0.0;
  double rad_per_s = 0.0;
  double sweep = 0.0;
  double k2 = 0.0;  ///< bound of |d2p/ds2| over the arc
  double k3 = 0.0;  ///< bound of |d3p/ds3| over the arc
  /// Bound of (d2p/ds2 . dp/ds) / k2: 0 on circles and helices, where the centripetal and the
  /// tangential acceleration are orthogonal.
  double cross = 0.0;

  [[nodiscard]] Point position(double s) const noexcept;
  [[nodiscard]] Point tangent(double s) const noexcept;    ///< dp/ds
  [[nodiscard]] Point curvature(double s) const noexcept;  ///< d2p/ds2
  /// position, tangent and curvature at once, from one sine and cosine (a Newton step on an arc
  /// needs all three; the three functions above take their member of it on an arc).
  struct Derivatives {
    Point position{};
    Point tangent{};
    Point curvature{};
  };
  [[nodiscard]] Derivatives derivatives(double s) const noexcept;
};

Geometry make_line(const Point& start, const Point& end) noexcept;
/// Throws core::InputError (line of the block) when the start or end lies on the centre.
Geometry make_arc(const Block& block, const Point& start);

/// Constant limits of a stretch of path: speed, tangential acceleration and jerk (kInfinity =
/// no jerk limit, trapezoidal profile).
struct PieceLimits {
  double v = 0.0;
  double a = 0.0;
  double j = kInfinity;
};

/// Limits on a segment when the acceleration vector may use `accel` and the jerk vector `jerk`.
PieceLimits segment_limits(const Geometry& g, double feed, double accel, double jerk, double ratio);

struct Segment {
  Geometry geo;
  std::size_t block = 0;   ///< index in Program::blocks
  double feed = 0.0;       ///< speed limit from the program [mm/s]
  double s_begin = 0.0;    ///< path position of the start along the whole program
  bool stop_before = false;  ///< exact stop at the start (program start, dwell, sharp corner)
  PathControl control = PathControl::Unstated;  ///< the block's mode: it governs the junction at the end
};

struct Dwell {
  std::size_t block = 0;
  std::size_t after_segments = 0;  ///< number of segments before the dwell
  double seconds = 0.0;
};

struct Path {
  Point start{};
  std::vector<Segment> segments;
  std::vector<Dwell> dwells;
};

/// Blocks -> segments and dwells. Validates the blocks (feeds, coordinates, continuity).
Path build_path(const Program& program, const InterpolationLimits& limits);

/// A stretch of one segment with constant limits.
struct Piece {
  std::uint32_t segment = 0;
  double s0 = 0.0;  ///< segment-local start
  double s1 = 0.0;  ///< segment-local end
  PieceLimits lim;
  /// Cap on the speed at the start of the piece from the junction before it (kInfinity: none;
  /// 0 at exact stops).
  double cap_before = kInfinity;
  /// The piece continues the previous one's profile (a smooth junction between equal limits):
  /// no boundary speed, no zero-acceleration point in S-curve mode.
  bool joins_previous = false;
};

/// Marks sharp corners as exact stops (Segment::stop_before), caps the junction speeds and
/// splits the segments into pieces with the zone-reduced limits.
std::vector<Piece> make_pieces(Path& path, const InterpolationLimits& limits);

/// One polynomial phase of the feed profile: s(tau) = s + v tau + a tau^2 / 2 + j tau^3 / 6 for
/// tau = t - t0, t in [t0, t1] (chain-local, unscaled time); s is segment-local.
struct Phase {
  double t0 = 0.0;
  double t1 = 0.0;
  std::uint32_t segment = 0;
  double s = 0.0;
  double v = 0.0;
  double a = 0.0;
  double j = 0.0;
};

/// A chain between two exact stops (or a dwell when phase_begin == phase_end): `samples`
/// sample periods starting at sample `first_sample`; its unscaled duration `duration` is mapped
/// onto samples * ts.
struct Span {
  std::size_t first_sample = 0;
  std::size_t samples = 0;
  double duration = 0.0;
  std::size_t phase_begin = 0;
  std::size_t phase_end = 0;
  Point end{};
};

struct PlanData {
  InterpolationLimits limits;
  std::uint8_t used_axes = 0;
  Point start{};
  Point end{};
  std::vector<Segment> segments;
  std::vector<Phase> phases;
  std::vector<Span> spans;
  std::vector<PlannedMove> moves;
  std::size_t sample_count = 1;
};

// ---- profile helpers (interpolation_profiles.cpp) ----

/// Time to change speed by dv >= 0 starting and ending with zero acceleration.
double change_time(double dv, double accel, double jerk) noexcept;
/// Distance covered while changing speed from v0 to v1 (either direction).
double change_distance(double v0, double v1, double accel, double jerk) noexcept;
/// Largest v1 >= v0 reachable from v0 within distance len.
double reach_speed(double v0, double len, double accel, double jerk) noexcept;
/// Largest peak speed in [max(v0, v1), vmax] of an accelerate-cruise-decelerate profile that
/// fits into len.
double peak_speed(double v0, double v1, double len, const PieceLimits& lim) noexcept;

/// Plans the profiles of all chains, fills phases, spans, moves and the sample count.
void plan_profiles(const Path& path, const std::vector<Piece>& pieces, const Program& program, PlanData& plan);

/// Path position along the whole program (Segment::s_begin + segment-local s) at every sample of
/// the plan, walked like sample_into (interpolation_sampling.cpp).
std::vector<double> sample_path_positions(const PlanData& plan);

/// Evaluates the path position of a phase at chain-local time t.
inline double phase_position(const Phase& p, double t) noexcept {
  const double tau = t - p.t0;
  return p.s + tau * (p.v + tau * (0.5 * p.a + tau * (p.j / 6.0)));
}
inline double phase_speed(const Phase& p, double t) noexcept {
  const double tau = t - p.t0;
  return p.v + tau * (p.a + tau * (0.5 * p.j));
}

}  // namespace servotwin::motion::detail
