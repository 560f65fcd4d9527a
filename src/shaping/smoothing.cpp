#include "servotwin/shaping/smoothing.hpp"

#include <cmath>
#include <limits>

#include "servotwin/core/error.hpp"
#include "shaper_checks.hpp"

namespace servotwin::shaping {
namespace {

void check_non_negative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0)
    throw core::InputError(core::at_field(name), "expected a finite value >= 0, got " + detail::show(value));
}

}  // namespace

SmoothingOffsets smoothing_offsets(const Shaper& shaper, double accel, double scv) {
  check_non_negative(accel, "accel");
  check_non_negative(scv, "scv");
  const std::size_t n = shaper.times.size();
  if (n == 0 || n != shaper.amplitudes.size())
    throw core::InputError(core::at_field("shaper"), "expected as many impulse times as amplitudes (at least one)");
  double sum = 0.0;
  double moment = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += shaper.amplitudes[i];
    moment += shaper.amplitudes[i] * shaper.times[i];
  }
  if (!(sum > 0.0)) throw core::InputError(core::at_field("shaper.amplitudes"), "expected amplitudes with a positive sum");
  const double centroid = moment / sum;
  const double half_accel = 0.5 * accel;
  double x_leg = 0.0;  // arriving axis: positions before the corner, reached by impulses after the centroid
  double y_leg = 0.0;  // leaving axis: positions after the corner, reached by impulses before the centroid
  double reversal = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double tau = shaper.times[i] - centroid;
    const double a = shaper.amplitudes[i];
    if (tau >= 0.0)
      x_leg += a * (scv + half_accel * tau) * tau;
    else
      y_leg += a * (scv - half_accel * tau) * (-tau);
    reversal += a * half_accel * tau * tau;
  }
  return {std::hypot(x_leg, y_leg) / sum, reversal / sum};
}

double shaper_smoothing(const Shaper& shaper, double accel, double scv) {
  return smoothing_offsets(shaper, accel, scv).smoothing();
}

std::optional<double> reachable_max_accel(const Shaper& shaper, double max_smoothing, double scv) {
  if (!std::isfinite(max_smoothing) || max_smoothing <= 0.0)
    throw core::InputError(core::at_field("max_smoothing"), "expected a length > 0, got " + detail::show(max_smoothing));
  if (shaper_smoothing(shaper, 0.0, scv) > max_smoothing) return std::nullopt;
  if (shaper.duration() == 0.0) return std::numeric_limits<double>::infinity();  // a single impulse never smooths
  double low = 0.0;
  double high = 1.0;
  while (shaper_smoothing(shaper, high, scv) <= max_smoothing) {
    low = high;
    high *= 2.0;
  }
  while (high - low > 1e-9 * high) {
    const double mid = 0.5 * (low + high);
    (shaper_smoothing(shaper, mid, scv) <= max_smoothing ? low : high) = mid;
  }
  return low;
}

double max_accel_for_smoothing(const Shaper& shaper, double max_smoothing, double scv) {
  if (const std::optional<double> accel = reachable_max_accel(shaper, max_smoothing, scv)) return *accel;
  throw core::InputError(core::at_field("max_smoothing"),
                         detail::show(max_smoothing) + " is below the smoothing " +
                             detail::show(shaper_smoothing(shaper, 0.0, scv)) +
                             " this shaper has at zero acceleration and scv = " + detail::show(scv) +
                             "; no acceleration meets it");
}

}  // namespace servotwin::shaping
