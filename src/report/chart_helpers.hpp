#pragma once
// Chart helpers shared by the reports (internal to the module): frequency charts, flat lines, dB
// of complex series, the time grid of step responses, the point-count check of the options.

#include <cmath>
#include <complex>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "bode.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/report/document.hpp"

namespace servotwin::report::detail {

inline Chart frequency_chart(std::string title, std::string y_label, Scale y_scale = Scale::Linear) {
  Chart c;
  c.title = std::move(title);
  c.x_label = "frequency [Hz]";
  c.y_label = std::move(y_label);
  c.x_scale = Scale::Log;
  c.y_scale = y_scale;
  return c;
}

/// A horizontal line over the chart's frequency span (two points; the chart spans the gaps).
inline Series flat(std::string label, const std::vector<double>& x, double y) {
  return {std::move(label), {x.front(), x.back()}, {y, y}};
}

inline std::vector<double> db_of(const std::vector<std::complex<double>>& g, double scale = 1.0) {
  std::vector<double> out = magnitude_db(g);
  const double offset = 20.0 * std::log10(scale);
  for (double& v : out) v += offset;
  return out;
}

struct TimeGrid {
  double dt = 0.0;  ///< normalized
  std::size_t samples = 0;
};

/// The analysis' horizon (15 time constants of the slowest closed-loop pole) at its step, or at a
/// coarser step when that would need more than `max_samples` (the samples stay exact: a step is
/// held constant between them).
inline TimeGrid time_grid(double horizon, double sample_time, std::size_t max_samples) {
  TimeGrid g;
  g.dt = sample_time;
  g.samples = static_cast<std::size_t>(std::ceil(horizon / sample_time)) + 1;
  if (g.samples > max_samples) {
    g.samples = max_samples;
    g.dt = horizon / static_cast<double>(max_samples - 1);
  }
  return g;
}

inline std::vector<double> scaled(std::vector<double> v, double factor) {
  for (double& x : v) x *= factor;
  return v;
}

/// Options' point counts: InputError naming "frequency_points"/"time_points" below `minimum`.
inline void check_point_counts(std::size_t frequency_points, std::size_t time_points, std::size_t minimum) {
  if (frequency_points < minimum)
    throw core::InputError(core::at_field("frequency_points"),
                           fmt::format("expected at least {} points, got {}", minimum, frequency_points));
  if (time_points < minimum)
    throw core::InputError(core::at_field("time_points"),
                           fmt::format("expected at least {} samples, got {}", minimum, time_points));
}

}  // namespace servotwin::report::detail
