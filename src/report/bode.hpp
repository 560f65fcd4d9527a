#pragma once
// Bode-plot helpers shared by the reports (internal to the report module).

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

namespace servotwin::report::detail {

/// Phase in degrees, continuous along the grid (the first point in (-180, 180]).
inline std::vector<double> unwrapped_phase_deg(const std::vector<std::complex<double>>& g) {
  std::vector<double> phase(g.size());
  double previous = 0.0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    const double p = std::arg(g[i]) * 180.0 / std::numbers::pi;
    if (i == 0 || !std::isfinite(previous)) {
      phase[i] = p;
    } else {
      double step = p - std::remainder(previous, 360.0);
      step = std::remainder(step, 360.0);
      phase[i] = previous + step;
    }
    previous = phase[i];
  }
  return phase;
}

/// 20 log10 |g| per point.
inline std::vector<double> magnitude_db(const std::vector<std::complex<double>>& g) {
  std::vector<double> db(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) db[i] = 20.0 * std::log10(std::abs(g[i]));
  return db;
}

}  // namespace servotwin::report::detail
