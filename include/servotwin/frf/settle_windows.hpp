#pragma once
/// \file
/// The settling test on windows of half-period means, beside RfidBlock's test on single estimates
/// half a period apart (issue 25 §1's 30 s, and points that are steady but noisy or still ring).
///
/// The single test compares the running estimate P̂ with its value half a period earlier. Two kinds
/// of points defeat it: a point whose response is small against the sensor noise (the half-period
/// change stays several times the allowance although P is steady: it waits for a lucky pair or for
/// its time limit), and a point beside a lightly damped mode, whose estimate carries the mode's
/// ringing as a slow beat (the change is small at the beat's turning points, so it passes by
/// chance with the ringing still in). Means over W half periods average the noise by √W and the
/// beat over its period; the test here compares the means of the last two windows and requires the
/// last window's standard error (the spread of its half-period means over √W) to be within twice
/// the same bound. W = 2, 4, 8, … up to a length the owner sets (RfidBlock: 0.25 s, so the test
/// acts above 4 Hz and leaves the long low-frequency periods to the single test). RfidBlock uses
/// it both ways: a window that passes settles a point the single test holds up (noise), and where
/// windows can be formed a single pass needs a window that passes too (ringing).
///
/// Fixed storage: no allocation per sample (a real-time block's member).

#include <array>
#include <complex>
#include <cstddef>

namespace servotwin::frf {

class SettleWindows {
 public:
  /// Half-period means kept; the longest window is half of it.
  static constexpr std::size_t kCapacity = 512;

  /// Forgets everything (a new frequency or a changed amplitude: a new transient).
  void clear() noexcept;
  /// One sample of the running estimate.
  void add(std::complex<double> running) noexcept;
  /// Ends the current half period: its mean becomes the newest stored one.
  void close_half_period() noexcept;
  /// Half-period means stored since the last clear (at most kCapacity).
  [[nodiscard]] std::size_t count() const noexcept;

  struct Verdict {
    bool settled = false;
    std::complex<double> mean;  ///< the passing window's mean (valid when settled)
  };
  /// The shortest window W ∈ {2, 4, 8, …} (W ≤ max_window, 2W means stored) whose mean differs
  /// from the previous W means' by at most relative·|mean| + absolute, its standard error within
  /// twice that.
  [[nodiscard]] Verdict test(double relative, double absolute, std::size_t max_window) const noexcept;
  /// The mean of the longest window W ∈ {2, 4, …} ≤ max_window that is stored; `fallback` when
  /// fewer than two means are.
  [[nodiscard]] std::complex<double> longest_mean(std::size_t max_window, std::complex<double> fallback) const noexcept;

 private:
  /// Running totals of the means and of their squared moduli since the last clear: a window's
  /// sums are the difference of two, so the test costs O(log W) per half period, not O(W).
  struct Totals {
    std::complex<double> sum;
    double norm = 0.0;
  };
  /// The totals of the k-th newest mean and all older ones (zero when k ≥ the means pushed).
  [[nodiscard]] Totals totals_through(std::size_t k) const noexcept;
  /// Sums over the means k ∈ [first, first + w) counted from the newest (first + w ≤ count()).
  [[nodiscard]] Totals window(std::size_t first, std::size_t w) const noexcept;

  /// One slot more than the means kept: a window reaching the oldest kept mean subtracts the
  /// totals just before it.
  std::array<Totals, kCapacity + 1> totals_{};
  std::size_t pushed_ = 0;  ///< means stored since the last clear (may exceed kCapacity: a ring)
  std::complex<double> sum_;
  long samples_ = 0;
  /// The first mean after a clear: the totals accumulate the means' differences from it, so that
  /// Σ|m|² − w|mean|² does not lose the spread to a large early mean.
  std::complex<double> reference_;
};

}  // namespace servotwin::frf
