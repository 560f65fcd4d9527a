#include "servotwin/frf/settle_windows.hpp"

#include <algorithm>
#include <cmath>

namespace servotwin::frf {

void SettleWindows::clear() noexcept {
  pushed_ = 0;
  sum_ = {};
  samples_ = 0;
}

void SettleWindows::add(std::complex<double> running) noexcept {
  sum_ += running;
  ++samples_;
}

void SettleWindows::close_half_period() noexcept {
  if (samples_ == 0) return;
  if (pushed_ == 0) reference_ = sum_ / static_cast<double>(samples_);
  const std::complex<double> mean = sum_ / static_cast<double>(samples_) - reference_;
  const Totals previous = totals_through(0);
  totals_[pushed_ % totals_.size()] = {previous.sum + mean, previous.norm + std::norm(mean)};
  ++pushed_;
  sum_ = {};
  samples_ = 0;
}

std::size_t SettleWindows::count() const noexcept { return std::min(pushed_, kCapacity); }

SettleWindows::Totals SettleWindows::totals_through(std::size_t k) const noexcept {
  return k >= pushed_ ? Totals{} : totals_[(pushed_ - 1 - k) % totals_.size()];
}

SettleWindows::Totals SettleWindows::window(std::size_t first, std::size_t w) const noexcept {
  const Totals to = totals_through(first), from = totals_through(first + w);
  return {to.sum - from.sum, to.norm - from.norm};
}

SettleWindows::Verdict SettleWindows::test(double relative, double absolute, std::size_t max_window) const noexcept {
  const std::size_t stored = count();
  for (std::size_t w = 2; w <= max_window && 2 * w <= stored; w *= 2) {
    const Totals last_window = window(0, w);
    const double n = static_cast<double>(w);
    // Sums of differences from reference_: the window means are reference_ + sum/w.
    const std::complex<double> last = last_window.sum / n, previous = window(w, w).sum / n;
    const double bound = relative * std::abs(reference_ + last) + absolute;
    if (std::abs(last - previous) > bound) continue;
    // Σ|m − mean|² = Σ|m|² − w|mean|² (of the differences), floored at 0 (rounding).
    const double spread = std::max(0.0, last_window.norm - n * std::norm(last));
    const double standard_error = std::sqrt(spread / (n - 1.0) / n);
    if (standard_error <= 2.0 * bound) return {true, reference_ + last};
  }
  return {};
}

std::complex<double> SettleWindows::longest_mean(std::size_t max_window, std::complex<double> fallback) const noexcept {
  std::size_t w = 0;
  for (std::size_t next = 2; next <= max_window && next <= count(); next *= 2) w = next;
  return w == 0 ? fallback : reference_ + window(0, w).sum / static_cast<double>(w);
}

}  // namespace servotwin::frf
