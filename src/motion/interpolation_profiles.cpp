// Interpolation step 3: feed profiles. Per chain of pieces between two exact stops: forward and
// backward pass over the boundary speeds, accelerate / cruise / decelerate per piece
// (trapezoidal or S-curve with zero acceleration at the piece ends), then the time scaling that
// puts the chain's end on a sample.
#include <algorithm>
#include <cmath>
#include <string>

#include "gcode_common.hpp"
#include "interpolation_detail.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::motion::detail {

double change_time(double dv, double accel, double jerk) noexcept {
  if (!std::isfinite(jerk)) return dv / accel;
  if (dv * jerk >= accel * accel) return dv / accel + accel / jerk;
  return 2.0 * std::sqrt(dv / jerk);
}

double change_distance(double v0, double v1, double accel, double jerk) noexcept {
  // The speed curve of a change between two rest points of the acceleration is point
  // symmetric about its middle, so the mean speed is (v0 + v1) / 2.
  return 0.5 * (v0 + v1) * change_time(std::abs(v1 - v0), accel, jerk);
}

namespace {

/// The largest v <= v1 (and >= v0) whose speed change from v0 fits into len when evaluated in
/// floating point. With a jerk limit the distance grows like sqrt(v - v0) for small changes, so
/// one ulp of a speed can move the distance by far more than an ulp of len; making every planned
/// change fit exactly lets the cruise absorb the remainder, and the profile of every piece then
/// ends exactly at its end.
double fitting_speed(double v0, double v1, double len, double accel, double jerk) noexcept {
  for (int i = 0; i < 64 && v1 > v0 && change_distance(v0, v1, accel, jerk) > len; ++i) v1 = std::nextafter(v1, v0);
  if (v1 > v0 && change_distance(v0, v1, accel, jerk) > len) {
    double lo = v0;
    double hi = v1;
    for (int it = 0; it < 200 && std::nextafter(lo, hi) < hi; ++it) {
      const double mid = lo + 0.5 * (hi - lo);
      (change_distance(v0, mid, accel, jerk) <= len ? lo : hi) = mid;
    }
    v1 = lo;
  }
  return std::max(v1, v0);
}

double reach_speed_raw(double v0, double len, double accel, double jerk) noexcept {
  if (!std::isfinite(jerk)) return std::sqrt(v0 * v0 + 2.0 * accel * len);
  const double a2 = accel * accel;
  const double len_full = (2.0 * v0 + a2 / jerk) * accel / jerk;  // distance at dv = accel^2 / jerk
  if (len <= len_full) {
    // (2 v0 + x^2) x = len sqrt(jerk) with x = sqrt(dv): Newton from an upper bound of the root
    // of this increasing convex cubic converges monotonically from above.
    const double q = len * std::sqrt(jerk);
    double x = v0 > 0.0 ? std::min(std::cbrt(q), q / (2.0 * v0)) : std::cbrt(q);
    for (int i = 0; i < 100; ++i) {
      const double f = (x * x + 2.0 * v0) * x - q;
      const double next = x - f / (3.0 * x * x + 2.0 * v0);
      if (!(next < x)) break;
      x = next;
    }
    return v0 + x * x;
  }
  // jerk dv^2 + b dv - c = 0, stable form of the positive root.
  const double b = 2.0 * v0 * jerk + a2;
  const double c = 2.0 * len * accel * jerk - 2.0 * v0 * a2;
  return v0 + 2.0 * c / (b + std::sqrt(b * b + 4.0 * jerk * c));
}

}  // namespace

double reach_speed(double v0, double len, double accel, double jerk) noexcept {
  if (len <= 0.0) return v0;
  return fitting_speed(v0, reach_speed_raw(v0, len, accel, jerk), len, accel, jerk);
}

double peak_speed(double v0, double v1, double len, const PieceLimits& lim) noexcept {
  const double lo_bound = std::max(v0, v1);
  if (lo_bound >= lim.v) return lo_bound;
  const auto needed = [&](double vp) {
    return change_distance(v0, vp, lim.a, lim.j) + change_distance(vp, v1, lim.a, lim.j);
  };
  if (needed(lim.v) <= len) return lim.v;
  if (needed(lo_bound) >= len) return lo_bound;
  double vp = lo_bound;
  if (!std::isfinite(lim.j)) {
    vp = std::clamp(std::sqrt(0.5 * (2.0 * lim.a * len + v0 * v0 + v1 * v1)), lo_bound, lim.v);
    // The closed form may miss by rounding: step down to a peak that fits in floating point.
    for (int i = 0; i < 64 && vp > lo_bound && needed(vp) > len; ++i) vp = std::nextafter(vp, lo_bound);
    if (needed(vp) <= len) return vp;
  }
  // needed() increases with vp: bisection keeping the end that fits.
  double lo = lo_bound;
  double hi = lim.v;
  for (int it = 0; it < 200 && std::nextafter(lo, hi) < hi; ++it) {
    const double mid = lo + 0.5 * (hi - lo);
    (needed(mid) <= len ? lo : hi) = mid;
  }
  return lo;
}

namespace {

/// Appends the phases of a speed change from v_from to v_to on one segment; t and s advance.
void push_change(std::vector<Phase>& out, std::uint32_t segment, double& t, double& s, double v_from, double v_to,
                 const PieceLimits& lim) {
  const double dv = std::abs(v_to - v_from);
  if (dv == 0.0) return;
  const double sign = v_to > v_from ? 1.0 : -1.0;
  const double total = change_time(dv, lim.a, lim.j);
  const double s_end = s + 0.5 * (v_from + v_to) * total;
  if (!std::isfinite(lim.j)) {
    out.push_back({t, t + total, segment, s, v_from, sign * lim.a, 0.0});
  } else {
    double ramp = 0.0;   // duration of each jerk phase
    double hold = 0.0;   // duration at constant acceleration
    if (dv * lim.j >= lim.a * lim.a) {
      ramp = lim.a / lim.j;
      hold = dv / lim.a - ramp;
    } else {
      ramp = std::sqrt(dv / lim.j);
    }
    const double jerks[3] = {sign * lim.j, 0.0, -sign * lim.j};
    const double durations[3] = {ramp, hold, ramp};
    double ps = s;
    double pv = v_from;
    double pa = 0.0;
    double pt = t;
    for (int k = 0; k < 3; ++k) {
      const double d = durations[k];
      if (d <= 0.0) continue;
      const double j = jerks[k];
      out.push_back({pt, pt + d, segment, ps, pv, pa, j});
      ps += d * (pv + d * (0.5 * pa + d * j / 6.0));
      pv += d * (pa + 0.5 * d * j);
      pa += d * j;
      pt += d;
    }
  }
  t += total;
  s = s_end;
}

/// Checks that adding `more` samples keeps the trajectory within the sample budget.
std::size_t checked_samples(double duration, double ts, std::size_t so_far, std::size_t max_samples) {
  const double count = std::ceil(duration / ts * (1.0 - 1e-12));
  if (!(count <= static_cast<double>(max_samples)) || so_far + static_cast<std::size_t>(count) > max_samples)
    throw core::InputError(core::SourceLocation{"", 0, 0, "max_samples"},
                           "the program would need more than " + std::to_string(max_samples) +
                               " samples at ts = " + format_number(ts) + " s");
  return std::max<std::size_t>(1, static_cast<std::size_t>(count));
}

struct ChainResult {
  double duration = 0.0;
  std::vector<double> piece_t0;  ///< chain-local start time of every piece, plus the end
  std::vector<double> piece_v0;  ///< speed at the start of every piece, plus the end speed
};

/// Pieces [p0, p1) planned as one profile (they continue each other's profile).
struct Unit {
  std::size_t p0 = 0;
  std::size_t p1 = 0;
  double len = 0.0;
  PieceLimits lim;
  double cap_before = kInfinity;
};

/// Time at which phase r reaches unit-local position s_target, in [t_lo, r.t1]; the position
/// is monotone there (speeds are >= 0), so bisection is safe.
double crossing_time(const Phase& r, double t_lo, double s_target) noexcept {
  double lo = t_lo;
  double hi = r.t1;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * std::max(std::abs(hi), 1e-300); ++it) {
    const double mid = 0.5 * (lo + hi);
    (phase_position(r, mid) < s_target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// Appends the part [ta, tb] of unit-local phase r as a phase of piece p, whose unit-local
/// start is `offset`.
void emit_part(const Phase& r, double ta, double tb, const Piece& p, double offset, std::vector<Phase>& out) {
  const double tau = ta - r.t0;
  out.push_back({ta, tb, p.segment, p.s0 + (phase_position(r, ta) - offset), phase_speed(r, ta), r.a + tau * r.j, r.j});
}

/// Plans pieces [p0, p1) between two exact stops and appends their phases.
ChainResult plan_chain(const std::vector<Piece>& pieces, std::size_t p0, std::size_t p1, std::vector<Phase>& phases) {
  std::vector<Unit> units;
  for (std::size_t i = p0; i < p1; ++i) {
    const Piece& p = pieces[i];
    if (i == p0 || !p.joins_previous) units.push_back({i, i, 0.0, p.lim, p.cap_before});
    units.back().p1 = i + 1;
    units.back().len += p.s1 - p.s0;
  }
  const std::size_t n = units.size();
  std::vector<double> b(n + 1, 0.0);
  for (std::size_t k = 1; k < n; ++k) b[k] = std::min({units[k].cap_before, units[k - 1].lim.v, units[k].lim.v});
  for (std::size_t k = 1; k < n; ++k) b[k] = std::min(b[k], reach_speed(b[k - 1], units[k - 1].len, units[k - 1].lim.a, units[k - 1].lim.j));
  for (std::size_t k = n - 1; k >= 1; --k) b[k] = std::min(b[k], reach_speed(b[k + 1], units[k].len, units[k].lim.a, units[k].lim.j));

  ChainResult r;
  r.piece_t0.assign(p1 - p0 + 1, 0.0);
  r.piece_v0.assign(p1 - p0 + 1, 0.0);
  std::vector<Phase> raw;
  double t = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const Unit& u = units[k];
    // Profile in unit-local position.
    raw.clear();
    const double vp = peak_speed(b[k], b[k + 1], u.len, u.lim);
    double s = 0.0;
    const double t_start = t;
    push_change(raw, 0, t, s, b[k], vp, u.lim);
    const double cruise = u.len - change_distance(b[k], vp, u.lim.a, u.lim.j) - change_distance(vp, b[k + 1], u.lim.a, u.lim.j);
    if (cruise > 0.0 && vp > 0.0) {
      const double d = cruise / vp;
      raw.push_back({t, t + d, 0, s, vp, 0.0, 0.0});
      t += d;
      s += cruise;
    }
    push_change(raw, 0, t, s, vp, b[k + 1], u.lim);
    // Cut the phases where they pass from one piece into the next.
    std::size_t i = u.p0;
    double offset = 0.0;
    double piece_end = pieces[i].s1 - pieces[i].s0;
    r.piece_t0[i - p0] = t_start;
    r.piece_v0[i - p0] = b[k];
    for (const Phase& ph : raw) {
      double ta = ph.t0;
      while (i + 1 < u.p1 && phase_position(ph, ph.t1) > piece_end) {
        const double tc = std::max(ta, crossing_time(ph, ta, piece_end));
        emit_part(ph, ta, tc, pieces[i], offset, phases);
        ++i;
        offset = piece_end;
        piece_end += pieces[i].s1 - pieces[i].s0;
        r.piece_t0[i - p0] = tc;
        r.piece_v0[i - p0] = phase_speed(ph, tc);
        ta = tc;
      }
      emit_part(ph, ta, ph.t1, pieces[i], offset, phases);
    }
    // Pieces the profile did not reach by rounding (only possible for a vanishing remainder).
    for (++i; i < u.p1; ++i) {
      r.piece_t0[i - p0] = t;
      r.piece_v0[i - p0] = b[k + 1];
    }
  }
  r.piece_t0[p1 - p0] = t;
  r.piece_v0[p1 - p0] = 0.0;
  r.duration = t;
  return r;
}

}  // namespace

void plan_profiles(const Path& path, const std::vector<Piece>& pieces, const Program& program, PlanData& plan) {
  const InterpolationLimits& lim = plan.limits;
  const double ts = lim.ts;
  std::size_t sample = 0;
  std::size_t next_dwell = 0;
  Point here = path.start;
  plan.phases.reserve(pieces.size() * 7);

  const auto emit_dwells = [&](std::size_t segments_done) {
    for (; next_dwell < path.dwells.size() && path.dwells[next_dwell].after_segments <= segments_done; ++next_dwell) {
      const Dwell& d = path.dwells[next_dwell];
      Span span;
      span.first_sample = sample;
      span.samples = checked_samples(d.seconds, ts, sample, lim.max_samples);
      span.duration = static_cast<double>(span.samples) * ts;
      span.phase_begin = span.phase_end = plan.phases.size();
      span.end = here;
      plan.spans.push_back(span);
      PlannedMove m;
      m.block = d.block;
      m.line = program.blocks[d.block].line;
      m.type = BlockType::Dwell;
      m.t_start = static_cast<double>(sample) * ts;
      sample += span.samples;
      m.t_end = static_cast<double>(sample) * ts;
      m.stop_at_end = true;
      plan.moves.push_back(m);
    }
  };

  std::size_t p = 0;
  while (p < pieces.size()) {
    const std::size_t first_segment = pieces[p].segment;
    emit_dwells(first_segment);
    std::size_t q = p + 1;
    while (q < pieces.size() && pieces[q].cap_before != 0.0) ++q;
    Span span;
    span.phase_begin = plan.phases.size();
    const ChainResult chain = plan_chain(pieces, p, q, plan.phases);
    span.phase_end = plan.phases.size();
    span.first_sample = sample;
    span.samples = checked_samples(chain.duration, ts, sample, lim.max_samples);
    span.duration = chain.duration;
    const std::uint32_t last_segment = pieces[q - 1].segment;
    span.end = path.segments[last_segment].geo.end;
    plan.spans.push_back(span);
    // Time scaling onto whole samples: t = first_sample ts + tau k, speeds / k.
    const double k = static_cast<double>(span.samples) * ts / chain.duration;
    const double t_base = static_cast<double>(sample) * ts;
    for (std::size_t i = p; i < q; ++i) {
      const std::size_t local = i - p;
      const Segment& seg = path.segments[pieces[i].segment];
      const bool first_of_segment = i == p || pieces[i - 1].segment != pieces[i].segment;
      const bool last_of_segment = i + 1 == q || pieces[i + 1].segment != pieces[i].segment;
      if (first_of_segment) {
        PlannedMove m;
        m.block = seg.block;
        m.line = program.blocks[seg.block].line;
        m.type = program.blocks[seg.block].type;
        m.length = seg.geo.length;
        m.feed = seg.feed;
        m.t_start = t_base + chain.piece_t0[local] * k;
        m.v_start = chain.piece_v0[local] / k;
        plan.moves.push_back(m);
      }
      if (last_of_segment) {
        PlannedMove& m = plan.moves.back();
        m.t_end = i + 1 == q ? static_cast<double>(sample + span.samples) * ts : t_base + chain.piece_t0[local + 1] * k;
        m.v_end = chain.piece_v0[local + 1] / k;
        m.stop_at_end = i + 1 == q;
      }
    }
    sample += span.samples;
    here = span.end;
    p = q;
  }
  emit_dwells(path.segments.size());
  plan.sample_count = sample + 1;
  plan.end = here;
}

}  // namespace servotwin::motion::detail
