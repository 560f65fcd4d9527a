#include "offline_support.hpp"

#include <cmath>
#include <string>

#include "servotwin/core/error.hpp"

namespace servotwin::frf::detail {

namespace {
void check_finite(std::span<const double> v, const char* name) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]))
      throw core::InputError(core::at_field(name), "sample " + std::to_string(i) + " is not finite");
}
}  // namespace

void check_signals(std::span<const double> x, std::span<const double> y, double ts) {
  if (!(std::isfinite(ts) && ts > 0.0)) throw core::InputError(core::at_field("ts"), "sample period must be > 0");
  if (x.size() != y.size())
    throw core::InputError(core::at_field("output"), "input and output differ in length (" + std::to_string(x.size()) +
                                                         " and " + std::to_string(y.size()) + " samples)");
  if (x.size() < 16)
    throw core::InputError(core::at_field("input"),
                           "at least 16 samples are needed for a frequency response, got " + std::to_string(x.size()));
  check_finite(x, "input");
  check_finite(y, "output");
  bool varies = false;
  for (double v : x) varies = varies || v != x.front();
  if (!varies)
    throw core::InputError(core::at_field("input"),
                           "the input is constant: nothing excites the system, so no frequency response can be estimated");
}

void detrend(std::vector<double>& v, Detrend kind) {
  if (kind == Detrend::kNone || v.empty()) return;
  const double n = static_cast<double>(v.size());
  double mean = 0.0;
  for (double s : v) mean += s;
  mean /= n;
  if (kind == Detrend::kMean) {
    for (double& s : v) s -= mean;
    return;
  }
  // Line a + b·(i − c) around the centre c, so the two coefficients are uncorrelated.
  const double c = 0.5 * (n - 1.0);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const double d = static_cast<double>(i) - c;
    sxy += d * (v[i] - mean);
    sxx += d * d;
  }
  const double slope = sxx > 0.0 ? sxy / sxx : 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) v[i] -= mean + slope * (static_cast<double>(i) - c);
}

}  // namespace servotwin::frf::detail
