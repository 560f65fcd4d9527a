#pragma once
/// \file
/// The real-time shaper filter (catalog C6.5, block "ZV4IS"): y[k] = Σ A_i u[k - d_i] with a
/// cyclic buffer, one sample at a time. Allocation-free and exception-free after construction
/// (design.md: everything that runs once per sample in a drive).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "servotwin/shaping/discretization.hpp"

namespace servotwin::shaping {

/// One channel. The ring buffer holds the last max_delay() + 1 inputs (rounded up to a power of
/// two so that wrapping is a mask).
class RealtimeShaper {
 public:
  /// Copies the pulses of `shaper` and fills the history with `initial` (the command's value before
  /// the first sample, so that a trajectory starting away from 0 does not see a jump). Throws
  /// core::InputError for a shaper without pulses, with mismatched delays/amplitudes, delays not
  /// strictly increasing from 0, or non-finite amplitudes.
  explicit RealtimeShaper(const DiscreteShaper& shaper, double initial = 0.0);

  /// Pushes one input sample and returns the shaped output of the same instant.
  double step(double x) noexcept {
    head_ = (head_ + 1) & mask_;
    buffer_[head_] = x;
    double y = 0.0;
    for (std::size_t i = 0; i < delays_.size(); ++i) y += amplitudes_[i] * buffer_[(head_ - delays_[i]) & mask_];
    return y;
  }

  /// step() over a block: out[k] = shaped in[k] for k < min(in.size(), out.size()); returns that
  /// count. `in` and `out` may be the same span (in-place).
  std::size_t process(std::span<const double> in, std::span<double> out) noexcept;

  /// Forgets the history: every past input equals `value`.
  void reset(double value = 0.0) noexcept;

  /// Largest delay [samples]: the output reaches a held input's value after it.
  [[nodiscard]] std::size_t max_delay() const noexcept { return delays_.empty() ? 0 : delays_.back(); }
  [[nodiscard]] std::size_t pulse_count() const noexcept { return delays_.size(); }
  /// Length of the ring buffer (a power of two >= max_delay() + 1).
  [[nodiscard]] std::size_t buffer_size() const noexcept { return buffer_.size(); }

 private:
  std::vector<std::size_t> delays_;
  std::vector<double> amplitudes_;
  std::vector<double> buffer_;
  std::size_t mask_ = 0;
  std::size_t head_ = 0;
};

/// The same shaper on several axes (one ring per axis), e.g. the X, Y, Z commands of a toolpath.
class MultiAxisShaper {
 public:
  /// `initial` holds each axis's value before the first sample; its size is the axis count
  /// (core::InputError when empty, plus RealtimeShaper's checks).
  MultiAxisShaper(const DiscreteShaper& shaper, std::span<const double> initial);

  /// One sample of every axis: out[i] = shaped in[i] for i < min(in.size(), out.size(), axes()).
  void step(std::span<const double> in, std::span<double> out) noexcept;
  void reset(std::span<const double> values) noexcept;

  [[nodiscard]] std::size_t axes() const noexcept { return channels_.size(); }
  [[nodiscard]] std::size_t max_delay() const noexcept { return channels_.front().max_delay(); }

 private:
  std::vector<RealtimeShaper> channels_;
};

}  // namespace servotwin::shaping
