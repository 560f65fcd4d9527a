// Contour error geometry: nearest points on the interpolator's own segment geometry (lines,
// circles, helices, spirals), restricted to the part of the path the command runs on near the
// query's sample; the command's progress along the path from a plan or from a recorded command.

#include "servotwin/motion/contour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "interpolation_detail.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/large_buffer.hpp"
#include "servotwin/core/parallel.hpp"

namespace servotwin::motion {

namespace detail {

/// A motion segment with the time span the commanded point runs on it, where it starts along
/// the whole path and its plane normal.
struct ContourSegment {
  Geometry geo;
  double s_begin = 0.0;  ///< path position of the start [mm]
  double feed = 0.0;     ///< programmed feed [mm/s]; 0 for rapids
  std::size_t line = 0;  ///< source line of the block
  double t_start = 0.0, t_end = 0.0;
  PathKind kind = PathKind::Line;
  std::size_t normal_axis = 2;  ///< plane normal: the side of a deviation is seen from +normal
  bool plain_circle = false;    ///< an arc of constant radius in its plane (no helix, no spiral)
};

}  // namespace detail

namespace {

using detail::ContourSegment;
using detail::Geometry;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
/// Path length around the commanded point, in multiples of the actual point's distance from it,
/// that a contour error is measured to. The nearest path point lies within twice that distance of
/// the commanded point (triangle inequality); along a curve the path between them is longer than
/// the straight line (a half circle: pi/2 times), hence 4.
constexpr double kPassReach = 4.0;

std::size_t normal_axis_of(Plane plane) noexcept {
  switch (plane) {
    case Plane::XY: return 2;
    case Plane::ZX: return 1;
    case Plane::YZ: return 0;
  }
  return 2;
}

double squared_distance(const Point& a, const Point& b) noexcept {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

bool finite(const Point& p) noexcept { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

/// Nearest point of a line segment's part [lo, hi]: the clamped orthogonal projection.
double nearest_on_line(const Geometry& g, const Point& p, double lo, double hi) noexcept {
  double s = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) s += (p[i] - g.start[i]) * g.dir[i];
  return std::clamp(s, lo, hi);
}

/// Nearest point of a circular arc's part [lo, hi] (constant radius, in its plane): the point at
/// the query's polar angle when that angle lies within the part, else the nearer end of the part.
double nearest_on_circle(const Geometry& g, const Point& p, double lo, double hi) noexcept {
  double u = 0.0, v = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    u += (p[i] - g.base[i]) * g.e1[i];
    v += (p[i] - g.base[i]) * g.e2[i];
  }
  if (u == 0.0 && v == 0.0) return lo;  // the centre: every point of the arc is nearest
  const double phi_lo = lo * g.rad_per_s, phi_hi = hi * g.rad_per_s;
  double phi = std::fmod(g.sense * (std::atan2(v, u) - g.angle0) - phi_lo, kTwoPi);
  if (phi < 0.0) phi += kTwoPi;
  phi += phi_lo;  // the query's angle in [phi_lo, phi_lo + 2 pi)
  if (phi <= phi_hi) return phi / g.rad_per_s;
  // Outside the part: the angular gap to each end decides (both ends lie on the same circle).
  const double past_end = phi - phi_hi, before_start = phi_lo + kTwoPi - phi;
  return past_end < before_start ? hi : lo;
}

/// Whether |p(phi) - q|^2 is strictly convex over the part [phi_lo, phi_hi] of a helix: constant
/// radius r, rise h along the axis (orthogonal to the plane), query at polar distance rho and
/// angle phi0 (in the arc's angle). There |p - q|^2 = r^2 + rho^2 - 2 r rho cos(phi - phi0)
/// + (h phi - w)^2, whose second derivative 2 r rho cos(phi - phi0) + 2 h^2 is positive wherever
/// the part stays within a quarter turn of phi0 (a margin of 1e-6 rad for rounding).
bool helix_part_is_convex(const Geometry& g, double phi0, double phi_lo, double phi_hi) noexcept {
  if (g.dr != 0.0) return false;
  double rise_in_plane = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i)
    rise_in_plane += std::abs(g.rise[i] * g.e1[i]) + std::abs(g.rise[i] * g.e2[i]);
  if (rise_in_plane != 0.0) return false;
  double from = std::remainder(phi_lo - phi0, kTwoPi);  // in [-pi, pi]
  const double to = from + (phi_hi - phi_lo);
  constexpr double kQuarter = std::numbers::pi / 2.0 - 1e-6;
  return from > -kQuarter && to < kQuarter;
}

/// Nearest point of a helix's or spiral's part [lo, hi]. The squared distance oscillates with the
/// polar angle, so every local minimum lies within half a turn of a parameter where the curve's
/// polar angle equals the query point's: Newton's method on d|p(s) - q|^2/ds = 0 from each of those
/// (and the two ends as candidates) finds them all; the smallest wins. Returns its parameter and
/// stores its point and tangent in `nearest` and `tangent` (sines and cosines the caller spares).
double nearest_on_curve(const Geometry& g, const Point& p, double lo, double hi, Point& nearest,
                        Point& tangent) noexcept {
  double u = 0.0, v = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    u += (p[i] - g.base[i]) * g.e1[i];
    v += (p[i] - g.base[i]) * g.e2[i];
  }
  double phi0 = std::fmod(g.sense * (std::atan2(v, u) - g.angle0), kTwoPi);
  if (phi0 < 0.0) phi0 += kTwoPi;
  const double phi_lo = lo * g.rad_per_s, phi_hi = hi * g.rad_per_s;
  double best_s = lo, best_d = kInfinity;
  const auto consider = [&](double s) {
    const Geometry::Derivatives at = g.derivatives(s);
    const double d = squared_distance(at.position, p);
    if (d < best_d) {
      best_d = d;
      best_s = s;
      nearest = at.position;
      tangent = at.tangent;
    }
  };
  // The ends are candidates unless the part is convex (helix_part_is_convex): then its one
  // minimum is Newton's, clamped to an end when it lies there (two sines fewer per query).
  if (!helix_part_is_convex(g, phi0, phi_lo, phi_hi)) {
    consider(lo);
    consider(hi);
  }
  // Starts: the parameters within half a turn of the part where the polar angle is the query's
  // (clamped into the part; a start repeated by the clamping is run once).
  double previous_start = -1.0;
  for (double phi = phi0 + kTwoPi * std::ceil((phi_lo - std::numbers::pi - phi0) / kTwoPi); phi <= phi_hi + std::numbers::pi;
       phi += kTwoPi) {
    const double start = std::clamp(phi, phi_lo, phi_hi);
    if (start == previous_start) continue;
    previous_start = start;
    double s = start / g.rad_per_s;
    for (int it = 0; it < 50; ++it) {
      const Geometry::Derivatives at = g.derivatives(s);
      double gt = 0.0, tt = 0.0, gk = 0.0;
      for (std::size_t i = 0; i < kAxisCount; ++i) {
        const double d = at.position[i] - p[i];
        gt += d * at.tangent[i];
        tt += at.tangent[i] * at.tangent[i];
        gk += d * at.curvature[i];
      }
      const double curvature = tt + gk;
      // Where the distance is locally concave, step downhill by the tangent alone.
      const double step = curvature > 0.0 ? gt / curvature : gt / tt;
      const double next = std::clamp(s - step, lo, hi);
      const bool done = std::abs(next - s) <= 1e-14 * (g.length + 1.0);
      s = next;
      if (done) break;
    }
    consider(s);
  }
  return best_s;
}

/// The nearest point of a segment's part [lo, hi]: its parameter, the point in `nearest` and the
/// path's tangent there in `tangent` (an arc's both from one sine and cosine).
double nearest_on_segment(const ContourSegment& seg, const Point& p, double lo, double hi, Point& nearest,
                          Point& tangent) noexcept {
  if (!seg.geo.is_arc) {
    const double s = nearest_on_line(seg.geo, p, lo, hi);
    nearest = seg.geo.position(s);
    tangent = seg.geo.dir;
    return s;
  }
  if (!seg.plain_circle) return nearest_on_curve(seg.geo, p, lo, hi, nearest, tangent);
  const double s = nearest_on_circle(seg.geo, p, lo, hi);
  const Geometry::Derivatives at = seg.geo.derivatives(s);
  nearest = at.position;
  tangent = at.tangent;
  return s;
}

/// Moves `q` (an open end of the path, `outward` = +1 at the end, -1 at the start) along the end
/// tangent `t` to the foot of p's perpendicular when p lies beyond that end.
void extend_past_end(const Point& t, double outward, const Point& p, Point& q) noexcept {
  double tt = 0.0, dt = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    tt += t[i] * t[i];
    dt += (p[i] - q[i]) * t[i];
  }
  if (!(tt > 0.0) || dt * outward <= 0.0) return;
  for (std::size_t i = 0; i < kAxisCount; ++i) q[i] += dt / tt * t[i];
}

/// +1 when d points to the left of the direction t (seen from +normal), else -1.
double side(const Point& t, const Point& d, std::size_t n) noexcept {
  const std::size_t a = (n + 1) % 3, b = (n + 2) % 3;
  const double cross_normal = t[a] * d[b] - t[b] * d[a];  // (t x d) . e_normal
  return cross_normal < 0.0 ? -1.0 : 1.0;
}

/// The program's segments (as the interpolator builds them) with their path positions.
std::vector<ContourSegment> segments_of(const Program& program, const detail::Path& path) {
  std::vector<ContourSegment> out;
  out.reserve(path.segments.size());
  for (const detail::Segment& s : path.segments) {
    ContourSegment seg;
    seg.geo = s.geo;
    seg.s_begin = s.s_begin;
    const BlockType type = program.blocks[s.block].type;
    seg.kind = type == BlockType::Rapid ? PathKind::Rapid : (type == BlockType::Linear ? PathKind::Line : PathKind::Arc);
    seg.feed = type == BlockType::Rapid ? 0.0 : program.blocks[s.block].feed_mm_min / 60.0;
    seg.line = program.blocks[s.block].line;
    seg.normal_axis = normal_axis_of(program.blocks[s.block].plane);
    seg.plain_circle = seg.geo.is_arc && seg.geo.dr == 0.0 && seg.geo.rise == Point{0.0, 0.0, 0.0};
    out.push_back(seg);
  }
  return out;
}

/// Index of the segment holding path position s (the last one starting at or before it).
std::size_t segment_at(const std::vector<ContourSegment>& segments, double s) noexcept {
  const auto it = std::upper_bound(segments.begin(), segments.end(), s,
                                   [](double v, const ContourSegment& seg) { return v < seg.s_begin; });
  return it == segments.begin() ? 0 : static_cast<std::size_t>(it - segments.begin()) - 1;
}

/// The program moved to start at `start`: the blocks up to the first motion start there.
Program starting_at(const Program& program, const Point& start) {
  Program p = program;
  p.start = start;
  for (Block& b : p.blocks) {
    b.start = start;
    if (b.type == BlockType::None || b.type == BlockType::Dwell) {
      b.end = start;
      b.center = start;
      continue;
    }
    break;
  }
  return p;
}

Point plus(const Point& a, const Point& b) noexcept { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Point minus(const Point& a, const Point& b) noexcept { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

/// Follows the command along the path: at each sample the nearest point of the path ahead of the
/// previous progress, within the distance the command moved plus `slack` (its deviation from the
/// path: blending, rounding). Among equally near candidates the earliest wins, so a back-and-forth
/// path (identification programs) is followed move by move.
struct Follower {
  const std::vector<ContourSegment>& segments;
  double slack;
  double tie;
  std::size_t current = 0;
  double progress = 0.0;

  /// Advances to sample point c (program coordinates); returns its squared distance to the path.
  double advance(const Point& c, double moved) noexcept {
    const double reach = progress + moved + slack;
    double best = kInfinity;
    std::size_t best_segment = current;
    double best_s = progress;
    for (std::size_t i = current; i < segments.size() && (i == current || segments[i].s_begin <= reach); ++i) {
      const ContourSegment& seg = segments[i];
      const double lo = std::max(0.0, progress - seg.s_begin);
      const double hi = std::clamp(reach - seg.s_begin, lo, seg.geo.length);
      Point q{}, tangent{};
      const double u = nearest_on_segment(seg, c, lo, hi, q, tangent);
      const double d = squared_distance(q, c);
      if (d + tie < best) {
        best = d;
        best_segment = i;
        best_s = seg.s_begin + u;
      }
    }
    current = best_segment;
    progress = std::max(progress, best_s);
    return best;
  }
};

struct Followed {
  std::vector<double> progress;
  CommandMatch match;
};

Followed follow(const std::vector<ContourSegment>& segments, const std::vector<Point>& points, const Point& offset,
                double slack, double scale) {
  Followed out;
  out.progress.reserve(points.size());
  Follower f{segments, slack, 1e-18 * scale * scale + 1e-30};
  double sum = 0.0;
  Point previous = minus(points.front(), offset);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Point c = minus(points[k], offset);
    const double d2 = f.advance(c, std::sqrt(squared_distance(c, previous)));
    previous = c;
    out.progress.push_back(f.progress);
    sum += d2;
    const double d = std::sqrt(d2);
    if (d > out.match.max_deviation) {
      out.match.max_deviation = d;
      out.match.worst_sample = k;
    }
  }
  out.match.offset = offset;
  out.match.rms_deviation = std::sqrt(sum / static_cast<double>(points.size()));
  out.match.progress_end = out.progress.back();
  const ContourSegment& last = segments.back();
  out.match.path_length = last.s_begin + last.geo.length;
  return out;
}

}  // namespace

const char* path_kind_name(PathKind kind) noexcept {
  switch (kind) {
    case PathKind::Line: return "line";
    case PathKind::Arc: return "arc";
    case PathKind::Rapid: return "rapid";
    case PathKind::Stop: return "stop";
    case PathKind::Move: return "move";
  }
  return "unknown";
}

ContourPath::ContourPath(const Program& program, const MotionPlan& plan, double window_s) {
  const detail::PlanData& data = plan.data();
  ts_ = plan.ts();
  window_s_ = window_s;
  duration_ = plan.duration();
  start_ = plan.start_point();
  progress_ = detail::sample_path_positions(data);
  // Each motion move of the plan has exactly one segment of the same block, in order.
  std::size_t next = 0;
  for (const PlannedMove& move : data.moves) {
    if (move.type == BlockType::Dwell) continue;
    while (next < data.segments.size() && data.segments[next].block != move.block) ++next;
    if (next == data.segments.size()) break;
    const detail::Segment& s = data.segments[next];
    ContourSegment seg;
    seg.geo = s.geo;
    seg.s_begin = s.s_begin;
    seg.t_start = move.t_start;
    seg.t_end = move.t_end;
    seg.kind = move.type == BlockType::Rapid ? PathKind::Rapid
               : (move.type == BlockType::Linear ? PathKind::Line : PathKind::Arc);
    seg.normal_axis = move.block < program.blocks.size() ? normal_axis_of(program.blocks[move.block].plane) : 2;
    seg.plain_circle = seg.geo.is_arc && seg.geo.dr == 0.0 && seg.geo.rise == Point{0.0, 0.0, 0.0};
    segments_.push_back(seg);
    ++next;
  }
  if (!segments_.empty()) match_.path_length = segments_.back().s_begin + segments_.back().geo.length;
  match_.progress_end = progress_.back();
}

ContourPath ContourPath::from_command(const Program& program, const Trajectory& command,
                                      const CommandMatchOptions& options) {
  const std::size_t n = command.size();
  if (n < 2) throw core::InputError("the recorded command has fewer than 2 samples");
  if (!(command.ts > 0.0)) throw core::InputError("the recorded command has no sample period");
  const std::uint8_t moved = program.used_axes();
  std::uint8_t given = 0;
  for (const Axis a : command.axes) given = static_cast<std::uint8_t>(given | axis_bit(a));
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    const Axis a = static_cast<Axis>(i);
    if ((moved & axis_bit(a)) != 0 && (given & axis_bit(a)) == 0)
      throw core::InputError(std::string("the program moves axis ") + axis_letter(a) +
                             " but the recorded command has no " + axis_name(a) + " column");
  }
  if (!(options.tolerance_mm >= 0.0) || !std::isfinite(options.tolerance_mm))
    throw core::InputError(core::at_field("tolerance_mm"), "must be a finite distance >= 0 mm");
  // Command samples as points; axes it does not give stay where the program starts.
  std::vector<Point> points(n, program.start);
  double scale = 0.0;
  for (std::size_t c = 0; c < command.axes.size(); ++c) {
    const auto a = static_cast<std::size_t>(command.axes[c]);
    for (std::size_t k = 0; k < n; ++k) {
      const double v = command.positions[c][k];
      if (!std::isfinite(v)) throw core::InputError("the recorded command has a non-finite sample at " + std::to_string(k));
      points[k][a] = v;
      scale = std::max(scale, std::abs(v));
    }
  }

  // The offset: the one given; else none, or, when that does not fit, the one that puts the
  // program's end on the command's last sample (a trace in machine coordinates, a work offset).
  ContourPath best;
  bool have = false;
  const auto try_offset = [&](const Point& offset) {
    const Program rebased = starting_at(program, minus(points.front(), offset));  // runs from where the trace starts
    const detail::Path path = detail::build_path(rebased, InterpolationLimits{});
    if (path.segments.empty()) throw core::InputError("the program has no motion: there is no path to follow");
    std::vector<ContourSegment> segments = segments_of(rebased, path);
    Followed f = follow(segments, points, offset, options.tolerance_mm, scale);
    if (have && f.match.rms_deviation >= best.match_.rms_deviation) return;
    best.segments_ = std::move(segments);
    best.progress_ = std::move(f.progress);
    best.match_ = f.match;
    best.offset_ = offset;
    best.start_ = plus(rebased.start, offset);
    have = true;
  };
  try_offset(options.offset.value_or(Point{0.0, 0.0, 0.0}));
  if (!options.offset && best.match_.max_deviation > options.tolerance_mm) {
    const Point end = best.segments_.back().geo.end;  // program coordinates
    try_offset(minus(points.back(), end));
  }
  best.ts_ = command.ts;
  best.window_s_ = options.window_s;
  best.duration_ = static_cast<double>(n - 1) * command.ts;
  // Kinds: the segment the command is on; Stop where it moves at less than 1 % of its top speed
  // (at rest, or within a few samples of an exact stop).
  std::vector<double> step(n);
  double top = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    step[k] = squared_distance(points[k == 0 ? 0 : k - 1], points[k + 1 < n ? k + 1 : k]);
    top = std::max(top, step[k]);
  }
  best.kinds_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const ContourSegment& seg = best.segments_[segment_at(best.segments_, best.progress_[k])];
    best.kinds_[k] = step[k] <= 1e-4 * top ? PathKind::Stop : seg.kind;
    // Speed over the programmed feed (central difference: 2 ts between the points).
    if (seg.feed <= 0.0 || k == 0 || k + 1 == n) continue;
    const double ratio = std::sqrt(step[k]) / (2.0 * command.ts) / seg.feed;
    if (ratio > best.match_.max_feed_ratio) {
      best.match_.max_feed_ratio = ratio;
      best.match_.feed_sample = k;
      best.match_.feed_line = seg.line;
      best.match_.feed_mm_min = 60.0 * seg.feed;
    }
  }
  // Segment time spans: the samples whose progress lies on them.
  for (ContourSegment& seg : best.segments_) {
    const auto first = std::lower_bound(best.progress_.begin(), best.progress_.end(), seg.s_begin);
    const auto last = std::upper_bound(best.progress_.begin(), best.progress_.end(), seg.s_begin + seg.geo.length);
    seg.t_start = static_cast<double>(first - best.progress_.begin()) * command.ts;
    seg.t_end = static_cast<double>(std::max(first, last - 1) - best.progress_.begin()) * command.ts;
  }
  return best;
}

ContourPath::~ContourPath() = default;
ContourPath::ContourPath(ContourPath&&) noexcept = default;
ContourPath& ContourPath::operator=(ContourPath&&) noexcept = default;

std::size_t ContourPath::segment_count() const noexcept { return segments_.size(); }

double ContourPath::progress_at(double t) const noexcept {
  if (progress_.empty()) return 0.0;
  const double x = std::clamp(t, 0.0, duration_) / ts_;
  const auto i = std::min(static_cast<std::size_t>(x), progress_.size() - 1);
  if (i + 1 >= progress_.size()) return progress_.back();
  const double f = x - static_cast<double>(i);
  return progress_[i] + f * (progress_[i + 1] - progress_[i]);
}

ContourPoint ContourPath::nearest_in(const Point& p_trace, double s_lo, double s_hi) const {
  if (segments_.empty()) throw core::InputError("the program has no motion: there is no path to measure a contour error to");
  if (!finite(p_trace)) throw core::InputError("contour error of a non-finite point");
  const Point p = minus(p_trace, offset_);
  const std::size_t first = segment_at(segments_, s_lo);
  ContourPoint best;
  double best_d2 = kInfinity, best_s = 0.0;
  Point best_tangent{};
  for (std::size_t i = first; i < segments_.size() && (i == first || segments_[i].s_begin <= s_hi); ++i) {
    const ContourSegment& seg = segments_[i];
    const double lo = std::clamp(s_lo - seg.s_begin, 0.0, seg.geo.length);
    const double hi = std::clamp(s_hi - seg.s_begin, lo, seg.geo.length);
    Point q{}, tangent{};
    const double s = nearest_on_segment(seg, p, lo, hi, q, tangent);
    const double d2 = squared_distance(q, p);
    if (d2 < best_d2) {
      best_d2 = d2;
      best_s = s;
      best.nearest = q;
      best.segment = i;
      best_tangent = tangent;
    }
  }
  // Past the path's open ends the path continues along its end tangent: what lies beyond the end
  // along the path is a positioning error, not a deviation from the contour.
  const ContourSegment& seg = segments_[best.segment];
  const bool at_start = best.segment == 0 && best_s <= 0.0;
  const bool at_end = best.segment + 1 == segments_.size() && best_s >= seg.geo.length;
  if (at_start || at_end) extend_past_end(best_tangent, at_start ? -1.0 : 1.0, p, best.nearest);
  best.distance = std::sqrt(squared_distance(best.nearest, p));
  best.signed_distance =
      best.distance == 0.0 ? 0.0 : best.distance * corner_side(best.segment, best_s, best_tangent, best.nearest, p);
  best.nearest = plus(best.nearest, offset_);
  return best;
}

double ContourPath::corner_side(std::size_t i, double s, const Point& tangent, const Point& q,
                                const Point& p) const noexcept {
  const ContourSegment& seg = segments_[i];
  Point t = tangent;
  // At a corner the side is seen from the direction halfway between the two segments' tangents,
  // so that a point past the corner (an overshoot) has the same side for both segments.
  if (s >= seg.geo.length && i + 1 < segments_.size()) t = plus(t, segments_[i + 1].geo.tangent(0.0));
  if (s <= 0.0 && i > 0) {
    const Geometry& before = segments_[i - 1].geo;
    t = plus(t, before.tangent(before.length));
  }
  return side(t, minus(p, q), seg.normal_axis);
}

ContourPoint ContourPath::nearest(const Point& p, double t, double window) const {
  const double w = std::max(window, 0.0);
  return nearest_in(p, progress_at(t - w), progress_at(t + w));
}

ContourPoint ContourPath::nearest(std::size_t k, const Point& p) const {
  if (segments_.empty()) throw core::InputError("the program has no motion: there is no path to measure a contour error to");
  if (!finite(p)) throw core::InputError("contour error of a non-finite point");
  const std::size_t kc = std::min(k, progress_.size() - 1);
  const double t = static_cast<double>(kc) * ts_;
  // The commanded point's place on the path, and the path within kPassReach times the point's
  // distance from it (see the file comment: other passes of the path stay out).
  const double s = progress_[kc];
  const ContourSegment& seg = segments_[segment_at(segments_, s)];
  const Point q = plus(seg.geo.position(std::clamp(s - seg.s_begin, 0.0, seg.geo.length)), offset_);
  const double reach = kPassReach * std::sqrt(squared_distance(p, q));
  return nearest_in(p, std::max(progress_at(t - window_s_), s - reach), std::min(progress_at(t + window_s_), s + reach));
}

PathKind ContourPath::kind_at(double t) const noexcept {
  if (!kinds_.empty()) {
    if (t < 0.0 || t > duration_) return PathKind::Stop;
    return kinds_[std::min(static_cast<std::size_t>(std::lround(t / ts_)), kinds_.size() - 1)];
  }
  const auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                                   [](double v, const ContourSegment& s) { return v < s.t_start; });
  if (it == segments_.begin()) return PathKind::Stop;
  const ContourSegment& s = *(it - 1);
  // The end time of a segment belongs to it only when the next one continues from there.
  return t < s.t_end ? s.kind : PathKind::Stop;
}

PathKind ContourPath::kind(std::size_t k) const noexcept {
  if (!kinds_.empty()) return k < kinds_.size() ? kinds_[k] : PathKind::Stop;
  return kind_at(static_cast<double>(k) * ts_);
}

// ---------------------------------------------------------------------------------------------

namespace {

/// Chords per block of the polyline's pruning: a block is skipped when the query's distance to its
/// first point minus its bounding radius exceeds the best distance so far.
constexpr std::size_t kBlock = 16;

/// Nearest point of the chord a -> b to p: parameter in [0, 1].
double chord_parameter(const Point& a, const Point& b, const Point& p) noexcept {
  double dot = 0.0, len2 = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    const double d = b[i] - a[i];
    dot += (p[i] - a[i]) * d;
    len2 += d * d;
  }
  return len2 > 0.0 ? std::clamp(dot / len2, 0.0, 1.0) : 0.0;
}

}  // namespace

CommandPolyline::CommandPolyline(const Trajectory& command, double window_s) {
  const std::size_t n = command.size();
  if (command.axes.empty() || n < 2) throw core::InputError("a recorded command path needs an axis and 2 samples");
  if (!(command.ts > 0.0) || !(window_s >= 0.0)) throw core::InputError("a recorded command path needs ts > 0 and a window >= 0");
  std::uint8_t given = 0;
  for (const Axis a : command.axes) given = static_cast<std::uint8_t>(given | axis_bit(a));
  has_side_ = command.axes.size() >= 2;
  normal_ = (given & axis_bit(Axis::Z)) == 0 ? 2 : (given & axis_bit(Axis::Y)) == 0 ? 1 : (given & axis_bit(Axis::X)) == 0 ? 0 : 2;
  points_.assign(n, Point{0.0, 0.0, 0.0});
  for (std::size_t c = 0; c < command.axes.size(); ++c) {
    const auto a = static_cast<std::size_t>(command.axes[c]);
    for (std::size_t k = 0; k < n; ++k) {
      if (!std::isfinite(command.positions[c][k]))
        throw core::InputError("the recorded command has a non-finite sample at " + std::to_string(k));
      points_[k][a] = command.positions[c][k];
    }
  }
  start_ = points_.front();
  window_ = static_cast<std::size_t>(std::llround(window_s / command.ts));
  arc_.resize(n);
  for (std::size_t k = 1; k < n; ++k) arc_[k] = arc_[k - 1] + std::sqrt(squared_distance(points_[k], points_[k - 1]));
  block_radius_.resize((n + kBlock - 1) / kBlock);
  for (std::size_t b = 0; b < block_radius_.size(); ++b) {
    const std::size_t first = b * kBlock, last = std::min(n - 1, first + kBlock);
    double r2 = 0.0;
    for (std::size_t k = first + 1; k <= last; ++k) r2 = std::max(r2, squared_distance(points_[k], points_[first]));
    block_radius_[b] = std::sqrt(r2);
  }
}

ContourPoint CommandPolyline::nearest(std::size_t k, const Point& p) const {
  if (!finite(p)) throw core::InputError("contour error of a non-finite point");
  const std::size_t n = points_.size();
  const std::size_t kc = std::min(k, n - 1);
  // Chords within the window and within kPassReach times the point's distance from the commanded
  // sample along the path (as ContourPath).
  const double pass = kPassReach * std::sqrt(squared_distance(p, points_[kc]));
  const auto first_near = static_cast<std::size_t>(
      std::lower_bound(arc_.begin(), arc_.end(), arc_[kc] - pass) - arc_.begin());
  const auto last_near = static_cast<std::size_t>(std::upper_bound(arc_.begin(), arc_.end(), arc_[kc] + pass) - arc_.begin());
  const std::size_t lo = std::max(kc > window_ ? kc - window_ : 0, first_near > 0 ? first_near - 1 : 0);
  const std::size_t hi = std::min({n - 1, kc + std::max<std::size_t>(window_, 1), std::max(last_near, kc + 1)});  // chords [lo, hi)
  double best_d2 = kInfinity;
  std::size_t best_chord = lo;
  double best_u = 0.0;
  const auto try_chord = [&](std::size_t i) {
    const double u = chord_parameter(points_[i], points_[i + 1], p);
    Point q{};
    for (std::size_t a = 0; a < kAxisCount; ++a) q[a] = points_[i][a] + u * (points_[i + 1][a] - points_[i][a]);
    const double d2 = squared_distance(q, p);
    if (d2 < best_d2) {
      best_d2 = d2;
      best_chord = i;
      best_u = u;
    }
  };
  // The chord at the query's own sample first: a good bound for the pruning.
  try_chord(std::min(kc, hi - 1));
  for (std::size_t b = lo / kBlock; b * kBlock < hi; ++b) {
    const std::size_t first = std::max(lo, b * kBlock), last = std::min(hi, (b + 1) * kBlock);
    const double reach = std::sqrt(squared_distance(p, points_[b * kBlock])) - block_radius_[b];
    if (reach > 0.0 && reach * reach > best_d2) continue;
    for (std::size_t i = first; i < last; ++i) try_chord(i);
  }
  ContourPoint out;
  const Point& a = points_[best_chord];
  const Point& b = points_[best_chord + 1];
  for (std::size_t i = 0; i < kAxisCount; ++i) out.nearest[i] = a[i] + best_u * (b[i] - a[i]);
  out.segment = best_chord;
  // Past the command's first and last sample the path continues along the chord (see ContourPath).
  const Point chord{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  if (best_chord == 0 && best_u <= 0.0) extend_past_end(chord, -1.0, p, out.nearest);
  if (best_chord + 2 == n && best_u >= 1.0) extend_past_end(chord, 1.0, p, out.nearest);
  out.distance = std::sqrt(squared_distance(out.nearest, p));
  Point t{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  // At a vertex the side is seen from the sum of the two chords' directions (see ContourPath).
  const double len = std::sqrt(squared_distance(a, b));
  if (len > 0.0) {
    for (double& c : t) c /= len;
    const auto add_chord = [&](std::size_t from) {
      const Point& u = points_[from];
      const Point& v = points_[from + 1];
      const double l = std::sqrt(squared_distance(u, v));
      if (l > 0.0)
        for (std::size_t c = 0; c < kAxisCount; ++c) t[c] += (v[c] - u[c]) / l;
    };
    if (best_u >= 1.0 && best_chord + 2 < n) add_chord(best_chord + 1);
    if (best_u <= 0.0 && best_chord > 0) add_chord(best_chord - 1);
  }
  const Point d{p[0] - out.nearest[0], p[1] - out.nearest[1], p[2] - out.nearest[2]};
  out.signed_distance = out.distance == 0.0 || !has_side_ ? out.distance : out.distance * side(t, d, normal_);
  return out;
}

PathKind CommandPolyline::kind(std::size_t k) const noexcept {
  const std::size_t n = points_.size();
  if (k >= n) return PathKind::Stop;
  const Point& a = points_[k == 0 ? 0 : k - 1];
  const Point& b = points_[k + 1 < n ? k + 1 : k];
  return a == b ? PathKind::Stop : PathKind::Move;
}

namespace {

/// Samples below which a part of a contour-error computation is not worth a thread.
constexpr std::size_t kSamplesPerPart = 8192;

/// Contour errors of the columns `actual` (checked), one query per sample.
template <typename Query>
std::vector<double> errors_by_sample(const Point& start, const std::vector<Axis>& axes,
                                     const std::vector<std::vector<double>>& actual, std::size_t workers, Query query) {
  if (axes.size() != actual.size())
    throw core::InputError("contour_errors: " + std::to_string(axes.size()) + " axes but " +
                           std::to_string(actual.size()) + " position columns");
  const std::size_t n = actual.empty() ? 0 : actual.front().size();
  for (const auto& column : actual) {
    if (column.size() != n) throw core::InputError("contour_errors: position columns differ in length");
  }
  std::vector<double> errors;
  core::reserve_large(errors, n);
  errors.resize(n);
  // Every sample's error depends on that sample alone: parts of the trace go to the cores.
  core::parallel_parts(n, workers, kSamplesPerPart, [&](std::size_t begin, std::size_t end) {
    Point p = start;
    for (std::size_t k = begin; k < end; ++k) {
      for (std::size_t i = 0; i < axes.size(); ++i) p[static_cast<std::size_t>(axes[i])] = actual[i][k];
      errors[k] = query(k, p);
    }
  });
  return errors;
}

}  // namespace

std::vector<double> contour_errors(const ContourReference& path, const std::vector<Axis>& axes,
                                   const std::vector<std::vector<double>>& actual, std::size_t workers) {
  return errors_by_sample(path.start_point(), axes, actual, workers,
                          [&](std::size_t k, const Point& p) { return path.nearest(k, p).signed_distance; });
}

std::vector<double> contour_errors_in_window(const ContourPath& path, const std::vector<Axis>& axes,
                                             const std::vector<std::vector<double>>& actual, double ts, double window) {
  return errors_by_sample(path.start_point(), axes, actual, 1, [&](std::size_t k, const Point& p) {
    return path.nearest(p, static_cast<double>(k) * ts, window).signed_distance;
  });
}

}  // namespace servotwin::motion
