// Shaped toolpath and its contour distortion (distance to the commanded polyline).
#include "servotwin/shaping/shaped_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "discrete_text.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/realtime_shaper.hpp"

namespace servotwin::shaping {

namespace {

using discrete_detail::num;

using core::at_field;
using core::InputError;

std::size_t checked_length(const Columns& columns, const char* what) {
  if (columns.empty()) throw InputError(at_field("positions"), "the " + std::string(what) + " trajectory has no axes");
  const std::size_t n = columns.front().size();
  if (n == 0) throw InputError(at_field("positions"), "the " + std::string(what) + " trajectory has no samples");
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i].size() != n)
      throw InputError(at_field("positions"), "axis " + num(i) + " of the " + std::string(what) + " trajectory has " +
                                                  num(columns[i].size()) + " samples, axis 0 has " + num(n));
    for (std::size_t k = 0; k < n; ++k)
      if (!std::isfinite(columns[i][k]))
        throw InputError(at_field("positions"), "axis " + num(i) + " of the " + std::string(what) +
                                                    " trajectory is not finite at sample " + num(k));
  }
  return n;
}

// Squared distance from point p (shaped sample k) to the segment between commanded samples j and
// j + 1 (a point when they coincide or j + 1 is past the end).
double squared_distance_to_segment(const Columns& path, std::size_t j, const Columns& points, std::size_t k) {
  const std::size_t n = path.front().size();
  const std::size_t j1 = std::min(j + 1, n - 1);
  double ab2 = 0.0, ap_ab = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double ab = path[i][j1] - path[i][j];
    ab2 += ab * ab;
    ap_ab += (points[i][k] - path[i][j]) * ab;
  }
  const double u = ab2 > 0.0 ? std::clamp(ap_ab / ab2, 0.0, 1.0) : 0.0;
  double d2 = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double nearest = path[i][j] + u * (path[i][j1] - path[i][j]);
    const double e = points[i][k] - nearest;
    d2 += e * e;
  }
  return d2;
}

}  // namespace

Columns shape_columns(const Columns& positions, const DiscreteShaper& shaper) {
  const std::size_t n = checked_length(positions, "commanded");
  const std::size_t extra = shaper.max_delay();
  Columns out(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    RealtimeShaper filter(shaper, positions[i].front());
    std::vector<double>& y = out[i];
    y.resize(n + extra);
    filter.process(positions[i], std::span<double>(y.data(), n));
    const double last = positions[i].back();
    for (std::size_t k = n; k < n + extra; ++k) y[k] = filter.step(last);
  }
  return out;
}

PathDeviation path_deviation(const Columns& commanded, const Columns& shaped, std::size_t max_delay,
                             std::optional<std::size_t> margin) {
  const std::size_t n = checked_length(commanded, "commanded");
  const std::size_t m = checked_length(shaped, "shaped");
  if (commanded.size() != shaped.size())
    throw InputError(at_field("positions"), "the commanded trajectory has " + num(commanded.size()) +
                                                " axes, the shaped one " + num(shaped.size()));
  const std::size_t w = margin.value_or(max_delay + 1);
  PathDeviation out;
  out.distance.resize(m);
  double sum2 = 0.0;
  for (std::size_t k = 0; k < m; ++k) {
    const std::size_t first = k > max_delay + w ? std::min(k - max_delay - w, n - 1) : 0;
    const std::size_t last = std::min(k + w, n - 1);
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_segment = first;
    for (std::size_t j = first; j <= last; ++j) {
      const double d2 = squared_distance_to_segment(commanded, j, shaped, k);
      if (d2 < best) {
        best = d2;
        best_segment = j;
      }
    }
    const double d = std::sqrt(best);
    out.distance[k] = d;
    sum2 += best;
    if (d > out.max || k == 0) {
      out.max = d;
      out.max_index = k;
      out.max_segment = best_segment;
    }
  }
  out.rms = std::sqrt(sum2 / static_cast<double>(m));
  out.max_point.reserve(shaped.size());
  for (const auto& column : shaped) out.max_point.push_back(column[out.max_index]);
  return out;
}

}  // namespace servotwin::shaping
