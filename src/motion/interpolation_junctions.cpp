// Interpolation step 2: junctions. Sharp corners become exact stops; continuous-feed junctions
// get speed caps and "zones" of reduced limits so that the sampled trajectory respects the
// limits when checked by finite differences (see interpolation.hpp for the argument):
//
//   * a velocity jump dv at a junction adds at most |dv| / ts to a second difference / ts^2 and
//     |dv| / ts^2 to a third difference / ts^3 (the second difference of a ramp is at most ts,
//     the third at most ts, for unit slope);
//   * an acceleration jump da adds at most (3/4) |da| / ts to a third difference / ts^3 (the
//     third difference of a unit parabola step (t - c)_+^2 / 2 is at most (3/4) ts^2);
//   * the regular motion inside the window adds at most the largest regular acceleration
//     (jerk) inside it, because a finite difference / ts^n is a weighted mean of the n-th
//     derivative with a B-spline kernel of unit mass.
//
// A window of w = 2 ts (3 ts for third differences) that contains junctions contains the one
// with the highest speed v*; the window lies within time w of it, so it covers a stretch of path
// of length at most w (v* + w accel) (the speed changes at most by accel per unit time) that
// contains that junction, and lies within that distance of it. So if, for every junction j, the
// jumps evaluated at v_j of the junctions in any stretch of that length containing j use at most
// a share s_j of the limit, and the regular motion within that distance of j is planned with
// (1 - s_j) of the limit, no finite difference exceeds the limit.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "interpolation_detail.hpp"

namespace servotwin::motion::detail {

namespace {

double norm(const Point& p) noexcept { return std::hypot(p[0], p[1], p[2]); }
Point minus(const Point& a, const Point& b) noexcept { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

/// Angle between two (non-zero) vectors, accurate near 0 and pi.
double angle_between(const Point& a, const Point& b) noexcept {
  const Point c{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  return std::atan2(norm(c), a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

/// A continuous-feed junction before segment `segment`.
struct Junction {
  std::size_t segment = 0;
  double s = 0.0;         ///< path position
  double dv_unit = 0.0;   ///< |p'_2 - p'_1|: velocity jump per unit speed
  double da_unit = 0.0;   ///< |p''_2 - p''_1|: acceleration jump per unit speed squared
  double vmax = 0.0;      ///< highest speed the adjacent segments allow
  double cap = kInfinity;
};

/// A stretch of path planned with reduced limits: accel * fa, jerk * fj.
struct Zone {
  double s0 = 0.0;
  double s1 = 0.0;
  double fa = 1.0;
  double fj = 1.0;
};

void mark_exact_stops(Path& path, const InterpolationLimits& limits) {
  const double corner = std::max(limits.corner_angle_deg * std::numbers::pi / 180.0, 1e-9);
  std::vector<bool> dwell_before(path.segments.size() + 1, false);
  for (const Dwell& d : path.dwells) dwell_before[d.after_segments] = true;
  for (std::size_t i = 0; i < path.segments.size(); ++i) {
    Segment& seg = path.segments[i];
    if (i == 0 || dwell_before[i] || limits.exact_stop_every_block) {
      seg.stop_before = true;
      continue;
    }
    const Segment& prev = path.segments[i - 1];
    // The previous block's mode governs the junction at its end (see Block::path_control).
    if (prev.control == PathControl::ExactStop) {
      seg.stop_before = true;
      continue;
    }
    const double limit = prev.control == PathControl::ExactPath ? 1e-9 : corner;
    seg.stop_before = angle_between(prev.geo.tangent(prev.geo.length), seg.geo.tangent(0.0)) > limit;
  }
}

/// Largest weighted jump sum over the stretches of path of length `len` that contain junction j:
/// max over l with s_l in [s_j - len, s_j] of the sum over junctions in [s_l, s_l + len] of
/// (wv dv_unit + wa da_unit). (A stretch can always be shifted until its start is a junction
/// without losing any.)
double window_max(const std::vector<double>& pos, const std::vector<double>& sum_dv, const std::vector<double>& sum_da,
                  std::size_t j, double len, double wv, double wa) noexcept {
  const auto first = static_cast<std::size_t>(std::lower_bound(pos.begin(), pos.end(), pos[j] - len) - pos.begin());
  std::size_t r = j + 1;
  double best = 0.0;
  for (std::size_t l = first; l <= j; ++l) {
    while (r < pos.size() && pos[r] <= pos[l] + len) ++r;
    best = std::max(best, wv * (sum_dv[r] - sum_dv[l]) + wa * (sum_da[r] - sum_da[l]));
  }
  return best;
}

/// Caps the speed of every junction and returns the zones of reduced limits around them.
std::vector<Zone> plan_junctions(std::vector<Junction>& junctions, const InterpolationLimits& limits) {
  const double ts = limits.ts;
  const double accel = limits.accel;
  const bool has_jerk = limits.jerk.has_value();
  const double jerk = has_jerk ? *limits.jerk : kInfinity;
  const double share = limits.junction_share;
  const std::size_t n = junctions.size();
  std::vector<double> positions(n);
  std::vector<double> sum_dv(n + 1, 0.0);
  std::vector<double> sum_da(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    positions[i] = junctions[i].s;
    sum_dv[i + 1] = sum_dv[i] + junctions[i].dv_unit;
    sum_da[i + 1] = sum_da[i] + junctions[i].da_unit;
  }
  // Path length a finite-difference window of duration w containing a junction passed at speed v
  // can span (the speed changes at most by accel per unit time), with a margin for the rounding
  // of the path positions. Second differences span 2 ts, third differences 3 ts.
  const auto span = [&](double w, double v) { return w * (v + w * accel) * (1.0 + 1e-9); };
  const double w_acc = 2.0 * ts;
  const double w_jerk = 3.0 * ts;
  // Shares of the acceleration and jerk limits used by the jumps in the worst window at speed v.
  const auto shares = [&](std::size_t j, double v) {
    const double sa = window_max(positions, sum_dv, sum_da, j, span(w_acc, v), v / ts, 0.0) / accel;
    const double sj =
        has_jerk ? window_max(positions, sum_dv, sum_da, j, span(w_jerk, v), v / (ts * ts), 0.75 * v * v / ts) / jerk : 0.0;
    return std::pair{sa, sj};
  };
  std::vector<Zone> zones;
  for (std::size_t j = 0; j < n; ++j) {
    Junction& jn = junctions[j];
    const auto fits = [&](double v) {
      const auto [sa, sj] = shares(j, v);
      return sa <= share && sj <= share;
    };
    double cap = jn.vmax;
    if (!fits(cap)) {
      // The shares grow monotonically with v (larger jumps, longer windows): bisection,
      // keeping the lower end, which fits.
      double lo = 0.0;
      double hi = cap;
      for (int it = 0; it < 100 && hi - lo > 1e-12 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        (fits(mid) ? lo : hi) = mid;
      }
      cap = lo;
    }
    jn.cap = cap;
    const auto [sa, sj] = shares(j, cap);
    if (sa > 0.0 || sj > 0.0) {
      // Everything a window containing this junction can reach is planned with the rest.
      const double d = span(has_jerk ? w_jerk : w_acc, cap);
      zones.push_back({jn.s - d, jn.s + d, 1.0 - sa, 1.0 - sj});
    }
  }
  return zones;
}

/// Splits one segment into pieces of constant limits according to the zone cuts on it.
void split_segment(std::uint32_t index, const Segment& seg, std::vector<Zone>& cuts,
                   const InterpolationLimits& limits, double cap_before, std::vector<Piece>& out) {
  const double len = seg.geo.length;
  const double jerk = limits.jerk ? *limits.jerk : kInfinity;
  std::vector<double> breaks{0.0, len};
  for (const Zone& c : cuts) {
    breaks.push_back(c.s0);
    breaks.push_back(c.s1);
  }
  std::sort(breaks.begin(), breaks.end());
  breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
  struct Stretch {
    double s0, s1, fa, fj;
  };
  std::vector<Stretch> stretches;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = breaks[k];
    const double b = breaks[k + 1];
    const double mid = 0.5 * (a + b);
    double fa = 1.0;
    double fj = 1.0;
    for (const Zone& c : cuts) {
      if (c.s0 <= mid && mid <= c.s1) {
        fa = std::min(fa, c.fa);
        fj = std::min(fj, c.fj);
      }
    }
    // Stretches at rounding level join their neighbour with the smaller factors (conservative).
    if (!stretches.empty() && (b - a <= 1e-9 * len || stretches.back().s1 - stretches.back().s0 <= 1e-9 * len)) {
      Stretch& last = stretches.back();
      last.s1 = b;
      last.fa = std::min(last.fa, fa);
      last.fj = std::min(last.fj, fj);
      continue;
    }
    if (!stretches.empty() && stretches.back().fa == fa && stretches.back().fj == fj) {
      stretches.back().s1 = b;
      continue;
    }
    stretches.push_back({a, b, fa, fj});
  }
  for (std::size_t k = 0; k < stretches.size(); ++k) {
    const Stretch& st = stretches[k];
    Piece p;
    p.segment = index;
    p.s0 = st.s0;
    p.s1 = st.s1;
    p.lim = segment_limits(seg.geo, seg.feed, limits.accel * st.fa, jerk * st.fj, limits.arc_tangential_ratio);
    p.cap_before = k == 0 ? cap_before : kInfinity;
    out.push_back(p);
  }
}

}  // namespace

std::vector<Piece> make_pieces(Path& path, const InterpolationLimits& limits) {
  mark_exact_stops(path, limits);
  const std::size_t n = path.segments.size();
  const double jerk = limits.jerk ? *limits.jerk : kInfinity;
  std::vector<PieceLimits> base(n);
  for (std::size_t i = 0; i < n; ++i)
    base[i] = segment_limits(path.segments[i].geo, path.segments[i].feed, limits.accel, jerk, limits.arc_tangential_ratio);

  std::vector<Junction> junctions;
  std::vector<bool> smooth(n, false);
  constexpr double kRounding = 16.0 * std::numeric_limits<double>::epsilon();
  for (std::size_t i = 1; i < n; ++i) {
    const Segment& seg = path.segments[i];
    if (seg.stop_before) continue;
    const Geometry& prev = path.segments[i - 1].geo;
    const Point k_prev = prev.curvature(prev.length);
    const Point k_next = seg.geo.curvature(0.0);
    Junction jn;
    jn.segment = i;
    jn.s = seg.s_begin;
    jn.dv_unit = norm(minus(seg.geo.tangent(0.0), prev.tangent(prev.length)));
    jn.da_unit = limits.jerk ? norm(minus(k_next, k_prev)) : 0.0;
    jn.vmax = std::min(base[i - 1].v, base[i].v);
    // Jumps at rounding level (collinear lines, an arc continuing on the same circle) are no
    // jumps: their effect on the finite differences is below that of rounding the positions.
    if (jn.dv_unit <= kRounding && jn.da_unit <= kRounding * std::max(norm(k_prev), norm(k_next))) {
      smooth[i] = true;
      continue;
    }
    junctions.push_back(jn);
  }
  const std::vector<Zone> zones = plan_junctions(junctions, limits);

  // Zone cuts per segment (segments are sorted by path position).
  std::vector<std::vector<Zone>> cuts(n);
  for (const Zone& z : zones) {
    auto it = std::upper_bound(path.segments.begin(), path.segments.end(), z.s0,
                               [](double s, const Segment& seg) { return s < seg.s_begin; });
    std::size_t i = it == path.segments.begin() ? 0 : static_cast<std::size_t>(it - path.segments.begin()) - 1;
    for (; i < n && path.segments[i].s_begin < z.s1; ++i) {
      const Segment& seg = path.segments[i];
      const double a = std::max(0.0, z.s0 - seg.s_begin);
      const double b = std::min(seg.geo.length, z.s1 - seg.s_begin);
      if (b > a) cuts[i].push_back({a, b, z.fa, z.fj});
    }
  }

  std::vector<double> caps(n, kInfinity);
  for (const Junction& jn : junctions) caps[jn.segment] = jn.cap;
  std::vector<Piece> pieces;
  pieces.reserve(n + 2 * zones.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double cap = path.segments[i].stop_before ? 0.0 : caps[i];
    const std::size_t first = pieces.size();
    split_segment(static_cast<std::uint32_t>(i), path.segments[i], cuts[i], limits, cap, pieces);
    // Across a smooth junction between equal limits the profile simply continues.
    if (smooth[i] && first > 0) {
      const PieceLimits& a = pieces[first - 1].lim;
      const PieceLimits& b = pieces[first].lim;
      pieces[first].joins_previous = a.v == b.v && a.a == b.a && a.j == b.j;
    }
  }
  return pieces;
}

}  // namespace servotwin::motion::detail
