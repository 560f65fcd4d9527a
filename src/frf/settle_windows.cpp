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
  means_[pushed_ % kCapacity] = sum_ / static_cast<double>(samples_);
  ++pushed_;
  sum_ = {};
  samples_ = 0;
}

std::size_t SettleWindows::count() const noexcept { return std::min(pushed_, kCapacity); }

std::complex<double> SettleWindows::newest(std::size_t k) const noexcept { return means_[(pushed_ - 1 - k) % kCapacity]; }

std::complex<double> SettleWindows::window_mean(std::size_t first, std::size_t w) const noexcept {
  std::complex<double> s;
  for (std::size_t k = first; k < first + w; ++k) s += newest(k);
  return s / static_cast<double>(w);
}

SettleWindows::Verdict SettleWindows::test(double relative, double absolute, std::size_t max_window) const noexcept {
  const std::size_t stored = count();
  for (std::size_t w = 2; w <= max_window && 2 * w <= stored; w *= 2) {
    const std::complex<double> last = window_mean(0, w), previous = window_mean(w, w);
    const double bound = relative * std::abs(last) + absolute;
    if (std::abs(last - previous) > bound) continue;
    double spread = 0.0;
    for (std::size_t k = 0; k < w; ++k) spread += std::norm(newest(k) - last);
    const double standard_error = std::sqrt(spread / static_cast<double>(w - 1) / static_cast<double>(w));
    if (standard_error <= 2.0 * bound) return {true, last};
  }
  return {};
}

std::complex<double> SettleWindows::longest_mean(std::size_t max_window, std::complex<double> fallback) const noexcept {
  std::size_t w = 0;
  for (std::size_t next = 2; next <= max_window && next <= count(); next *= 2) w = next;
  return w == 0 ? fallback : window_mean(0, w);
}

}  // namespace servotwin::frf
