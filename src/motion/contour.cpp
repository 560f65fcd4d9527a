// Contour error geometry: nearest points on the interpolator's own segment geometry (lines,
// circles, helices, spirals), restricted to the segments run near the query time.

#include "servotwin/motion/contour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "interpolation_detail.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::motion {

namespace detail {

/// A motion segment with the time span the commanded point runs on it and its plane normal.
struct ContourSegment {
  Geometry geo;
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

/// Nearest point of a line segment: the clamped orthogonal projection.
double nearest_on_line(const Geometry& g, const Point& p) noexcept {
  double s = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) s += (p[i] - g.start[i]) * g.dir[i];
  return std::clamp(s, 0.0, g.length);
}

/// Nearest point of a circular arc (constant radius, in its plane): the point at the query's
/// polar angle when that angle lies within the sweep, else the nearer end.
double nearest_on_circle(const Geometry& g, const Point& p) noexcept {
  double u = 0.0, v = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    u += (p[i] - g.base[i]) * g.e1[i];
    v += (p[i] - g.base[i]) * g.e2[i];
  }
  if (u == 0.0 && v == 0.0) return 0.0;  // the centre: every point of the arc is nearest
  double phi = std::fmod(g.sense * (std::atan2(v, u) - g.angle0), kTwoPi);
  if (phi < 0.0) phi += kTwoPi;
  if (phi <= g.sweep) return phi / g.rad_per_s;
  // Outside the sweep: the angular gap to each end decides (the ends lie on the same circle).
  const double past_end = phi - g.sweep, before_start = kTwoPi - phi;
  return past_end < before_start ? g.length : 0.0;
}

/// Nearest point of a helix or spiral. The squared distance oscillates with the polar angle, so
/// every local minimum lies within half a turn of a parameter where the curve's polar angle equals
/// the query point's: Newton's method on d|p(s) - q|^2/ds = 0 from each of those (and the two
/// ends as candidates) finds them all; the smallest wins.
double nearest_on_curve(const Geometry& g, const Point& p) noexcept {
  double u = 0.0, v = 0.0;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    u += (p[i] - g.base[i]) * g.e1[i];
    v += (p[i] - g.base[i]) * g.e2[i];
  }
  double phi0 = std::fmod(g.sense * (std::atan2(v, u) - g.angle0), kTwoPi);
  if (phi0 < 0.0) phi0 += kTwoPi;
  double best_s = 0.0, best_d = squared_distance(g.position(0.0), p);
  const auto consider = [&](double s) {
    const double d = squared_distance(g.position(s), p);
    if (d < best_d) {
      best_d = d;
      best_s = s;
    }
  };
  consider(g.length);
  for (double phi = phi0 - kTwoPi; phi <= g.sweep + kTwoPi; phi += kTwoPi) {
    double s = std::clamp(phi, 0.0, g.sweep) / g.rad_per_s;
    for (int it = 0; it < 50; ++it) {
      const Point q = g.position(s), t = g.tangent(s), k = g.curvature(s);
      double gt = 0.0, tt = 0.0, gk = 0.0;
      for (std::size_t i = 0; i < kAxisCount; ++i) {
        const double d = q[i] - p[i];
        gt += d * t[i];
        tt += t[i] * t[i];
        gk += d * k[i];
      }
      const double curvature = tt + gk;
      // Where the distance is locally concave, step downhill by the tangent alone.
      const double step = curvature > 0.0 ? gt / curvature : gt / tt;
      const double next = std::clamp(s - step, 0.0, g.length);
      const bool done = std::abs(next - s) <= 1e-14 * (g.length + 1.0);
      s = next;
      if (done) break;
    }
    consider(s);
  }
  return best_s;
}

double nearest_parameter(const ContourSegment& seg, const Point& p) noexcept {
  if (!seg.geo.is_arc) return nearest_on_line(seg.geo, p);
  if (seg.plain_circle) return nearest_on_circle(seg.geo, p);
  return nearest_on_curve(seg.geo, p);
}

/// + when p lies to the left of the direction of travel at q (seen from the plane's +normal).
double side_of(const ContourSegment& seg, double s, const Point& q, const Point& p) noexcept {
  const Point t = seg.geo.tangent(s);
  const Point d{p[0] - q[0], p[1] - q[1], p[2] - q[2]};
  const std::size_t n = seg.normal_axis, a = (n + 1) % 3, b = (n + 2) % 3;
  const double cross_normal = t[a] * d[b] - t[b] * d[a];  // (t x d) . e_normal
  return cross_normal < 0.0 ? -1.0 : 1.0;
}

}  // namespace

const char* path_kind_name(PathKind kind) noexcept {
  switch (kind) {
    case PathKind::Line: return "line";
    case PathKind::Arc: return "arc";
    case PathKind::Rapid: return "rapid";
    case PathKind::Stop: return "stop";
  }
  return "unknown";
}

ContourPath::ContourPath(const Program& program, const MotionPlan& plan) {
  const detail::PlanData& data = plan.data();
  duration_ = plan.duration();
  start_ = plan.start_point();
  // Each motion move of the plan has exactly one segment of the same block, in order.
  std::size_t next = 0;
  for (const PlannedMove& move : data.moves) {
    if (move.type == BlockType::Dwell) continue;
    while (next < data.segments.size() && data.segments[next].block != move.block) ++next;
    if (next == data.segments.size()) break;
    ContourSegment seg;
    seg.geo = data.segments[next].geo;
    seg.t_start = move.t_start;
    seg.t_end = move.t_end;
    seg.kind = move.type == BlockType::Rapid ? PathKind::Rapid
               : (move.type == BlockType::Linear ? PathKind::Line : PathKind::Arc);
    seg.normal_axis = move.block < program.blocks.size() ? normal_axis_of(program.blocks[move.block].plane) : 2;
    seg.plain_circle = seg.geo.is_arc && seg.geo.dr == 0.0 && seg.geo.rise == Point{0.0, 0.0, 0.0};
    segments_.push_back(seg);
    ++next;
  }
}

ContourPath::~ContourPath() = default;
ContourPath::ContourPath(ContourPath&&) noexcept = default;
ContourPath& ContourPath::operator=(ContourPath&&) noexcept = default;

std::size_t ContourPath::segment_count() const noexcept { return segments_.size(); }

ContourPoint ContourPath::nearest(const Point& p, double t, double window) const {
  if (segments_.empty()) throw core::InputError("the program has no motion: there is no path to measure a contour error to");
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    throw core::InputError("contour error of a non-finite point");
  const double tc = std::clamp(t, 0.0, duration_);
  const double w = std::max(window, 0.0);
  // Segments are in time order: [first, last] are those overlapping [tc - w, tc + w]; the one
  // running at (or last before) tc is always included.
  const auto first_it = std::lower_bound(segments_.begin(), segments_.end(), tc - w,
                                         [](const ContourSegment& s, double v) { return s.t_end < v; });
  const auto last_it = std::upper_bound(segments_.begin(), segments_.end(), tc + w,
                                        [](double v, const ContourSegment& s) { return v < s.t_start; });
  std::size_t first = static_cast<std::size_t>(first_it - segments_.begin());
  std::size_t last = static_cast<std::size_t>(last_it - segments_.begin());
  if (last == 0) last = 1;
  first = std::min(first, last - 1);

  ContourPoint best;
  double best_d2 = std::numeric_limits<double>::infinity();
  double best_s = 0.0;
  for (std::size_t i = first; i < last; ++i) {
    const double s = nearest_parameter(segments_[i], p);
    const Point q = segments_[i].geo.position(s);
    const double d2 = squared_distance(q, p);
    if (d2 < best_d2) {
      best_d2 = d2;
      best_s = s;
      best.nearest = q;
      best.segment = i;
    }
  }
  best.distance = std::sqrt(best_d2);
  best.signed_distance =
      best.distance == 0.0 ? 0.0 : best.distance * side_of(segments_[best.segment], best_s, best.nearest, p);
  return best;
}

PathKind ContourPath::kind_at(double t) const noexcept {
  const auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                                   [](double v, const ContourSegment& s) { return v < s.t_start; });
  if (it == segments_.begin()) return PathKind::Stop;
  const ContourSegment& s = *(it - 1);
  // The end time of a segment belongs to it only when the next one continues from there.
  return t < s.t_end ? s.kind : PathKind::Stop;
}

std::vector<double> contour_errors(const ContourPath& path, const std::vector<Axis>& axes,
                                   const std::vector<std::vector<double>>& actual, double ts, double window) {
  if (axes.size() != actual.size())
    throw core::InputError("contour_errors: " + std::to_string(axes.size()) + " axes but " +
                           std::to_string(actual.size()) + " position columns");
  const std::size_t n = actual.empty() ? 0 : actual.front().size();
  for (const auto& column : actual) {
    if (column.size() != n) throw core::InputError("contour_errors: position columns differ in length");
  }
  std::vector<double> errors(n);
  Point p = path.start_point();
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < axes.size(); ++i) p[static_cast<std::size_t>(axes[i])] = actual[i][k];
    errors[k] = path.nearest(p, static_cast<double>(k) * ts, window).signed_distance;
  }
  return errors;
}

}  // namespace servotwin::motion
