#include "servotwin/shaping/multimode.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "servotwin/core/error.hpp"
#include "shaper_checks.hpp"

namespace servotwin::shaping {
namespace {

void check_factor(const Shaper& shaper, const char* which) {
  const std::string field = std::string(which) + " shaper";
  if (shaper.times.empty() || shaper.times.size() != shaper.amplitudes.size())
    throw core::InputError(core::at_field(field),
                           "expected as many impulse times as amplitudes and at least one impulse, got " +
                               std::to_string(shaper.times.size()) + " times and " +
                               std::to_string(shaper.amplitudes.size()) + " amplitudes");
  double sum = 0.0;
  for (double a : shaper.amplitudes) sum += a;
  if (!(sum > 0.0) || !std::isfinite(sum))
    throw core::InputError(core::at_field(field), "expected amplitudes with a positive sum, got " + detail::show(sum));
}

}  // namespace

Shaper convolve_shapers(const Shaper& first, const Shaper& second, double merge_tolerance) {
  check_factor(first, "first");
  check_factor(second, "second");
  std::vector<std::pair<double, double>> pulses;
  pulses.reserve(first.times.size() * second.times.size());
  for (std::size_t i = 0; i < first.times.size(); ++i)
    for (std::size_t j = 0; j < second.times.size(); ++j)
      pulses.emplace_back(first.times[i] + second.times[j], first.amplitudes[i] * second.amplitudes[j]);
  std::sort(pulses.begin(), pulses.end());

  Shaper result{"multi", first.omega, first.zeta, {}, {}};
  double sum = 0.0;
  for (const auto& [time, amplitude] : pulses) {
    if (!result.times.empty() && time - result.times.back() <= merge_tolerance) {
      result.amplitudes.back() += amplitude;
    } else {
      result.times.push_back(time);
      result.amplitudes.push_back(amplitude);
    }
    sum += amplitude;
  }
  for (double& a : result.amplitudes) a /= sum;
  // Both factors start at 0, so the first impulse is at 0 up to rounding of the sum: make it exact.
  const double start = result.times.front();
  for (double& t : result.times) t -= start;
  return result;
}

Shaper convolve_shapers(const std::vector<Shaper>& shapers, double merge_tolerance) {
  if (shapers.empty()) throw core::InputError(core::at_field("shapers"), "expected at least one shaper to convolve");
  Shaper result = shapers.front();
  for (std::size_t k = 1; k < shapers.size(); ++k) result = convolve_shapers(result, shapers[k], merge_tolerance);
  return result;
}

}  // namespace servotwin::shaping
