// Interpolation step 1: blocks -> path segments (lines, circles, helices, spirals) and their
// speed/acceleration/jerk limits.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "interpolation_detail.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::motion::detail {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

core::SourceLocation at_line(const Block& b) { return core::SourceLocation{"", b.line, 0, ""}; }

std::string format_point(const Point& p) {
  return "(" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ", " + std::to_string(p[2]) + ")";
}

bool finite(const Point& p) noexcept {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

double max_abs(const Point& p) noexcept { return std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}); }

/// Axis indices (first, second, normal) of a plane, in the order in which a positive rotation
/// about the normal turns the first axis into the second (ISO: G17 XY, G18 ZX, G19 YZ).
std::array<std::size_t, 3> plane_axes(Plane plane) noexcept {
  switch (plane) {
    case Plane::XY: return {0, 1, 2};
    case Plane::ZX: return {2, 0, 1};
    case Plane::YZ: return {1, 2, 0};
  }
  return {0, 1, 2};
}

/// Positive root of k3 v^3 + p v = q (k3, p, q > 0). Newton's method from an upper bound
/// converges monotonically from above because the cubic is increasing and convex for v > 0.
double cubic_speed_root(double k3, double p, double q) noexcept {
  double v = std::min(std::cbrt(q / k3), q / p);
  for (int i = 0; i < 100; ++i) {
    const double f = (k3 * v * v + p) * v - q;
    const double next = v - f / (3.0 * k3 * v * v + p);
    if (!(next < v)) break;
    v = next;
  }
  return v;
}

}  // namespace

Point Geometry::position(double s) const noexcept {
  if (!is_arc) return {start[0] + s * dir[0], start[1] + s * dir[1], start[2] + s * dir[2]};
  return derivatives(s).position;
}

Point Geometry::tangent(double s) const noexcept {
  if (!is_arc) return dir;
  return derivatives(s).tangent;
}

Point Geometry::curvature(double s) const noexcept {
  if (!is_arc) return {0.0, 0.0, 0.0};
  return derivatives(s).curvature;
}

Geometry::Derivatives Geometry::derivatives(double s) const noexcept {
  if (!is_arc) return {position(s), dir, {0.0, 0.0, 0.0}};
  // Arc: p = base + r (cos a e1 + sin a e2) + phi rise; with e = c e1 + sn e2 and
  // e_perp = -sn e1 + c e2, dp/dphi = dr e + sense r e_perp + rise and
  // d2p/dphi2 = 2 dr sense e_perp - r e.
  const double phi = s * rad_per_s;
  const double a = angle0 + sense * phi;
  const double r = r0 + dr * phi;
  const double c = std::cos(a);
  const double sn = std::sin(a);
  const double rc = r * c;
  const double rs = r * sn;
  const double q = rad_per_s * rad_per_s;
  Derivatives d;
  for (std::size_t i = 0; i < kAxisCount; ++i) {
    d.position[i] = base[i] + rc * e1[i] + rs * e2[i] + phi * rise[i];
    d.tangent[i] = rad_per_s * (dr * (c * e1[i] + sn * e2[i]) + sense * r * (-sn * e1[i] + c * e2[i]) + rise[i]);
    d.curvature[i] = q * (2.0 * dr * sense * (-sn * e1[i] + c * e2[i]) - r * (c * e1[i] + sn * e2[i]));
  }
  return d;
}

Geometry make_line(const Point& start, const Point& end) noexcept {
  Geometry g;
  g.start = start;
  g.end = end;
  const Point d{end[0] - start[0], end[1] - start[1], end[2] - start[2]};
  g.length = std::hypot(d[0], d[1], d[2]);
  for (std::size_t i = 0; i < kAxisCount; ++i) g.dir[i] = d[i] / g.length;
  return g;
}

Geometry make_arc(const Block& block, const Point& start) {
  const auto [iu, iv, iw] = plane_axes(block.plane);
  Geometry g;
  g.is_arc = true;
  g.start = start;
  g.end = block.end;
  const double cu = block.center[iu];
  const double cv = block.center[iv];
  const double su = start[iu] - cu;
  const double sv = start[iv] - cv;
  const double eu = block.end[iu] - cu;
  const double ev = block.end[iv] - cv;
  const double r_start = std::hypot(su, sv);
  const double r_end = std::hypot(eu, ev);
  if (r_start == 0.0) throw core::InputError(at_line(block), "arc start point lies on the arc centre (radius 0)");
  if (r_end == 0.0) throw core::InputError(at_line(block), "arc end point lies on the arc centre (radius 0)");
  g.sense = block.type == BlockType::ArcCcw ? 1.0 : -1.0;
  g.angle0 = std::atan2(sv, su);
  if (start[iu] == block.end[iu] && start[iv] == block.end[iv]) {
    g.sweep = kTwoPi;
  } else {
    double sweep = std::fmod(g.sense * (std::atan2(ev, eu) - g.angle0), kTwoPi);
    if (sweep <= 0.0) sweep += kTwoPi;
    g.sweep = sweep;
  }
  g.r0 = r_start;
  g.dr = (r_end - r_start) / g.sweep;
  const double h = (block.end[iw] - start[iw]) / g.sweep;
  const double r_max = std::max(r_start, r_end);
  // |dp/dphi|^2 = dr^2 + r^2 + h^2 is largest at r_max: with s = phi * G the speed never
  // exceeds the planned path speed, and equals it on circles and helices.
  const double big_g = std::sqrt(g.dr * g.dr + r_max * r_max + h * h);
  g.rad_per_s = 1.0 / big_g;
  g.length = g.sweep * big_g;
  g.base[iu] = cu;
  g.base[iv] = cv;
  g.base[iw] = start[iw];
  g.e1[iu] = 1.0;
  g.e2[iv] = 1.0;
  g.rise[iw] = h;
  // d2p/dphi2 = 2 dr sense e_perp - r e, d3p/dphi3 = -3 dr e - sense r e_perp.
  g.k2 = std::sqrt(4.0 * g.dr * g.dr + r_max * r_max) / (big_g * big_g);
  g.k3 = std::sqrt(9.0 * g.dr * g.dr + r_max * r_max) / (big_g * big_g * big_g);
  // p'' . p' = dr r / G^3 (zero unless the radius changes).
  g.cross = std::min(1.0, std::abs(g.dr) * r_max / (big_g * big_g * big_g * g.k2));
  return g;
}

PieceLimits segment_limits(const Geometry& g, double feed, double accel, double jerk, double ratio) {
  if (!g.is_arc) return {feed, accel, jerk};
  PieceLimits lim;
  lim.a = ratio * accel;
  // |a|^2 <= (k2 v^2)^2 + a_t^2 + 2 cross (k2 v^2) a_t; with a_t = ratio accel and
  // k2 v^2 = c accel this is accel^2 for c solving c^2 + 2 cross ratio c + ratio^2 = 1.
  const double e = g.cross * ratio;
  const double c = std::sqrt(e * e + 1.0 - ratio * ratio) - e;
  lim.v = std::min(feed, std::sqrt(c * accel / g.k2));
  if (std::isfinite(jerk)) {
    lim.j = ratio * jerk;
    // |jerk| <= k3 v^3 + 3 k2 v a_t + j_t (rotating centripetal vector, cross term, tangential).
    lim.v = std::min(lim.v, cubic_speed_root(g.k3, 3.0 * g.k2 * lim.a, (1.0 - ratio) * jerk));
  }
  return lim;
}

Path build_path(const Program& program, const InterpolationLimits& limits) {
  Path path;
  path.start = program.start;
  if (!finite(program.start)) throw core::InputError("program start position is not finite");
  double scale = max_abs(program.start);
  for (const Block& b : program.blocks) {
    if (b.type == BlockType::None) continue;
    if (b.type == BlockType::Dwell) {
      if (!std::isfinite(b.dwell_s) || b.dwell_s < 0.0)
        throw core::InputError(at_line(b), "dwell must be a finite time >= 0 s, got " + std::to_string(b.dwell_s));
      continue;
    }
    if (!finite(b.start) || !finite(b.end) ||
        ((b.type == BlockType::ArcCw || b.type == BlockType::ArcCcw) && !finite(b.center)))
      throw core::InputError(at_line(b), "block has a non-finite coordinate");
    if (b.type != BlockType::Rapid && (!std::isfinite(b.feed_mm_min) || b.feed_mm_min <= 0.0))
      throw core::InputError(at_line(b), "feed must be > 0, got F" + std::to_string(b.feed_mm_min));
    scale = std::max({scale, max_abs(b.start), max_abs(b.end)});
  }
  // Blocks must start where the previous one ended; a mismatch at rounding level is accepted
  // and the path is kept continuous by starting at the previous end.
  const double tol = 1e-9 * scale;
  const double max_feed = limits.max_feed_mm_min / 60.0;
  Point current = program.start;
  double s_total = 0.0;
  for (std::size_t i = 0; i < program.blocks.size(); ++i) {
    const Block& b = program.blocks[i];
    if (b.type == BlockType::None) continue;
    if (b.type == BlockType::Dwell) {
      if (b.dwell_s > 0.0) path.dwells.push_back({i, path.segments.size(), b.dwell_s});
      continue;
    }
    for (std::size_t k = 0; k < kAxisCount; ++k)
      if (std::abs(b.start[k] - current[k]) > tol)
        throw core::InputError(at_line(b), "block starts at " + format_point(b.start) +
                                               " but the previous block ended at " + format_point(current));
    Segment seg;
    seg.block = i;
    seg.control = b.path_control;
    if (b.type == BlockType::Rapid || b.type == BlockType::Linear) {
      if (b.end == current) continue;  // zero-length move
      seg.geo = make_line(current, b.end);
    } else {
      seg.geo = make_arc(b, current);
    }
    seg.feed = b.type == BlockType::Rapid ? limits.rapid_feed_mm_min / 60.0 : std::min(b.feed_mm_min / 60.0, max_feed);
    seg.s_begin = s_total;
    s_total += seg.geo.length;
    path.segments.push_back(seg);
    current = b.end;
  }
  return path;
}

}  // namespace servotwin::motion::detail
