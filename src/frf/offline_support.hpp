#pragma once
// Private helpers of the offline estimators: argument checks and detrending.

#include <span>
#include <vector>

#include "servotwin/frf/offline.hpp"

namespace servotwin::frf::detail {

/// Same length, at least 16 samples, finite values, ts > 0, input not constant.
void check_signals(std::span<const double> x, std::span<const double> y, double ts);

/// Removes the mean or the least-squares line from `v` in place (scipy.signal.detrend).
void detrend(std::vector<double>& v, Detrend kind);

}  // namespace servotwin::frf::detail
