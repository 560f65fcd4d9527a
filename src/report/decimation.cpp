// Display decimation of long series (document.hpp): what a chart draws, never what a report
// computes its numbers from.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/report/document.hpp"

namespace servotwin::report {

namespace {

void require_budget(std::size_t max_points) {
  if (max_points < kMinDisplayPoints) {
    throw core::InputError({"", 0, 0, "max_points"}, "a series needs at least " + std::to_string(kMinDisplayPoints) +
                                                         " display points, got " + std::to_string(max_points));
  }
}

std::vector<std::size_t> all_indices(std::size_t n) {
  std::vector<std::size_t> out(n);
  std::iota(out.begin(), out.end(), std::size_t{0});
  return out;
}

/// Start of bucket b of `buckets` equal index buckets over [0, n).
std::size_t bucket_begin(std::size_t b, std::size_t buckets, std::size_t n) {
  // n and buckets are far below 2^32 in practice; the product stays within 64 bits up to there.
  return static_cast<std::size_t>(static_cast<unsigned long long>(b) * n / buckets);
}

/// Appends the sorted, distinct picks of one bucket after `out`'s last element.
void append_sorted(std::vector<std::size_t>& out, std::size_t* picks, std::size_t count) {
  // At most five picks: insertion sort (std::sort on such small arrays also trips GCC 12's
  // -Warray-bounds).
  for (std::size_t i = 1; i < count; ++i)
    for (std::size_t j = i; j > 0 && picks[j - 1] > picks[j]; --j) std::swap(picks[j - 1], picks[j]);
  for (std::size_t i = 0; i < count; ++i)
    if (out.empty() || picks[i] > out.back()) out.push_back(picks[i]);
}

bool finite_point(std::span<const double> x, std::span<const double> y, std::size_t k) {
  return std::isfinite(x[k]) && std::isfinite(y[k]);
}

/// Per index bucket: the extremes of x and of y and the first non-finite point (the fallback of
/// display_path_indices for paths broken into very many pieces).
std::vector<std::size_t> path_bucket_extremes(std::span<const double> x, std::span<const double> y,
                                              std::size_t max_points) {
  const std::size_t n = x.size();
  const std::size_t buckets = (max_points - 2) / 5;
  std::vector<std::size_t> out;
  out.reserve(max_points);
  out.push_back(0);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = bucket_begin(b, buckets, n), end = bucket_begin(b + 1, buckets, n);
    std::size_t picks[5];
    std::size_t count = 0;
    std::size_t lo_x = end, hi_x = end, lo_y = end, hi_y = end, gap = end;
    for (std::size_t k = begin; k < end; ++k) {
      if (!finite_point(x, y, k)) {
        if (gap == end) gap = k;
        continue;
      }
      if (lo_x == end || x[k] < x[lo_x]) lo_x = k;
      if (hi_x == end || x[k] > x[hi_x]) hi_x = k;
      if (lo_y == end || y[k] < y[lo_y]) lo_y = k;
      if (hi_y == end || y[k] > y[hi_y]) hi_y = k;
    }
    for (std::size_t k : {lo_x, hi_x, lo_y, hi_y, gap})
      if (k != end) picks[count++] = k;
    append_sorted(out, picks, count);
  }
  if (out.back() != n - 1) out.push_back(n - 1);
  return out;
}

/// Squared distance of p to the segment a-b (to the point a when a == b).
double segment_distance2(double px, double py, double ax, double ay, double bx, double by) {
  const double vx = bx - ax, vy = by - ay;
  const double length2 = vx * vx + vy * vy;
  double t = 0.0;
  if (length2 > 0.0) t = std::clamp(((px - ax) * vx + (py - ay) * vy) / length2, 0.0, 1.0);
  const double dx = px - (ax + t * vx), dy = py - (ay + t * vy);
  return dx * dx + dy * dy;
}

/// Douglas-Peucker with a point budget on the candidate points `c` (indices into x, y, ascending,
/// all finite): appends at most `budget` (>= 2) of them, always the first and the last.
void simplify_run(std::span<const double> x, std::span<const double> y, const std::vector<std::size_t>& c,
                  std::size_t budget, std::vector<std::size_t>& out) {
  struct Segment {
    double deviation2;
    std::size_t lo, hi, far;  // positions in c
    bool operator<(const Segment& other) const { return deviation2 < other.deviation2; }
  };
  auto farthest = [&](std::size_t lo, std::size_t hi) {
    Segment s{0.0, lo, hi, lo};
    const std::size_t a = c[lo], b = c[hi];
    for (std::size_t i = lo + 1; i < hi; ++i) {
      const double d = segment_distance2(x[c[i]], y[c[i]], x[a], y[a], x[b], y[b]);
      if (d > s.deviation2) {
        s.deviation2 = d;
        s.far = i;
      }
    }
    return s;
  };
  out.push_back(c.front());
  if (c.size() == 1) return;
  out.push_back(c.back());
  std::priority_queue<Segment> open;
  if (c.size() > 2) open.push(farthest(0, c.size() - 1));
  std::size_t kept = 2;
  while (kept < budget && !open.empty()) {
    const Segment s = open.top();
    open.pop();
    if (!(s.deviation2 > 0.0)) break;  // the simplified path is exact
    out.push_back(c[s.far]);
    ++kept;
    if (s.far - s.lo > 1) open.push(farthest(s.lo, s.far));
    if (s.hi - s.far > 1) open.push(farthest(s.far, s.hi));
  }
}

/// Candidates of a finite run [begin, end) for simplify_run: every point, or for runs far longer
/// than the budget the extremes of x and y in 16 x budget buckets (a point lost there deviates
/// from its neighbours by less than a bucket's extent, far below a pixel) so that the
/// simplification stays near linear in the run's length.
std::vector<std::size_t> run_candidates(std::span<const double> x, std::span<const double> y, std::size_t begin,
                                        std::size_t end, std::size_t budget) {
  const std::size_t n = end - begin;
  std::vector<std::size_t> c;
  if (n <= 64 * budget) {
    c.resize(n);
    std::iota(c.begin(), c.end(), begin);
    return c;
  }
  const std::size_t buckets = 16 * budget;
  c.reserve(4 * buckets + 2);
  c.push_back(begin);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t lo = begin + bucket_begin(b, buckets, n), hi = begin + bucket_begin(b + 1, buckets, n);
    std::size_t lo_x = lo, hi_x = lo, lo_y = lo, hi_y = lo;
    for (std::size_t k = lo + 1; k < hi; ++k) {
      if (x[k] < x[lo_x]) lo_x = k;
      if (x[k] > x[hi_x]) hi_x = k;
      if (y[k] < y[lo_y]) lo_y = k;
      if (y[k] > y[hi_y]) hi_y = k;
    }
    std::size_t picks[4] = {lo_x, hi_x, lo_y, hi_y};
    append_sorted(c, picks, 4);
  }
  if (c.back() != end - 1) c.push_back(end - 1);
  return c;
}

}  // namespace

std::vector<std::size_t> display_indices(std::span<const double> y, std::size_t max_points) {
  require_budget(max_points);
  const std::size_t n = y.size();
  if (n <= max_points) return all_indices(n);
  const bool has_gap = std::any_of(y.begin(), y.end(), [](double v) { return !std::isfinite(v); });
  // First and last sample, then per bucket minimum and maximum (and a gap marker).
  const std::size_t buckets = (max_points - 2) / (has_gap ? 3 : 2);
  std::vector<std::size_t> out;
  out.reserve(max_points);
  out.push_back(0);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = bucket_begin(b, buckets, n), end = bucket_begin(b + 1, buckets, n);
    std::size_t lo = end, hi = end, gap = end;
    for (std::size_t k = begin; k < end; ++k) {
      const double v = y[k];
      if (!std::isfinite(v)) {
        if (gap == end) gap = k;
      } else {
        if (lo == end || v < y[lo]) lo = k;
        if (hi == end || v > y[hi]) hi = k;
      }
    }
    std::size_t picks[3];
    std::size_t count = 0;
    for (std::size_t k : {lo, hi, gap})
      if (k != end) picks[count++] = k;
    append_sorted(out, picks, count);
  }
  if (out.back() != n - 1) out.push_back(n - 1);
  return out;
}

std::vector<std::size_t> display_path_indices(std::span<const double> x, std::span<const double> y,
                                              std::size_t max_points) {
  if (x.size() != y.size()) {
    throw core::InputError({"", 0, 0, "x"}, "a path needs as many x as y values, got " + std::to_string(x.size()) +
                                                " and " + std::to_string(y.size()));
  }
  require_budget(max_points);
  const std::size_t n = x.size();
  if (n <= max_points) return all_indices(n);

  // Stretches of finite points and the gaps between them.
  struct Run {
    std::size_t begin, end;
  };
  std::vector<Run> runs;
  std::vector<std::size_t> gaps;  // first index of each maximal non-finite stretch
  std::size_t finite = 0;
  for (std::size_t k = 0; k < n;) {
    std::size_t j = k;
    if (finite_point(x, y, k)) {
      while (j < n && finite_point(x, y, j)) ++j;
      runs.push_back({k, j});
      finite += j - k;
    } else {
      while (j < n && !finite_point(x, y, j)) ++j;
      gaps.push_back(k);
    }
    k = j;
  }
  if (gaps.size() + 2 * runs.size() > max_points / 2) return path_bucket_extremes(x, y, max_points);

  // Each run gets its end points, then a share of the rest in proportion to its length.
  const std::size_t budget = max_points - gaps.size();
  std::size_t base = 0;
  for (const Run& r : runs) base += std::min<std::size_t>(r.end - r.begin, 2);
  const std::size_t spare = budget - base;
  std::vector<std::size_t> out(gaps);
  out.reserve(max_points);
  for (const Run& r : runs) {
    const std::size_t length = r.end - r.begin;
    const std::size_t share = static_cast<std::size_t>(static_cast<unsigned long long>(spare) * length / finite);
    const std::size_t run_budget = std::min(length, std::min<std::size_t>(length, 2) + share);
    if (run_budget >= length) {
      for (std::size_t k = r.begin; k < r.end; ++k) out.push_back(k);
      continue;
    }
    simplify_run(x, y, run_candidates(x, y, r.begin, r.end, run_budget), run_budget, out);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace servotwin::report
