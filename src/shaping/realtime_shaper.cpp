// Real-time shaper filter: ring buffer of the last max_delay + 1 inputs.
#include "servotwin/shaping/realtime_shaper.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "discrete_text.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::shaping {

namespace {

using discrete_detail::num;

void validate(const DiscreteShaper& shaper) {
  using core::at_field;
  using core::InputError;
  if (shaper.delays.empty()) throw InputError(at_field("delays"), "the discrete shaper has no pulses");
  if (shaper.amplitudes.size() != shaper.delays.size())
    throw InputError(at_field("amplitudes"), "expected " + num(shaper.delays.size()) +
                                                 " amplitudes (one per delay), got " + num(shaper.amplitudes.size()));
  if (shaper.delays.front() != 0)
    throw InputError(at_field("delays[0]"), "the first delay must be 0, got " + num(shaper.delays.front()));
  for (std::size_t i = 0; i < shaper.delays.size(); ++i) {
    if (i > 0 && shaper.delays[i] <= shaper.delays[i - 1])
      throw InputError(
          at_field("delays[" + num(i) + "]"),
          "expected strictly increasing delays, got " + num(shaper.delays[i]) + " after " + num(shaper.delays[i - 1]));
    if (!std::isfinite(shaper.amplitudes[i]))
      throw InputError(at_field("amplitudes[" + num(i) + "]"), "expected a finite amplitude");
  }
  // Same bound as discretize(): a bigger buffer is not a real-time filter.
  if (shaper.delays.back() > 10'000'000)
    throw InputError(at_field("delays"), "delay of " + num(shaper.delays.back()) + " samples exceeds 10^7");
}

}  // namespace

RealtimeShaper::RealtimeShaper(const DiscreteShaper& shaper, double initial) {
  validate(shaper);
  delays_ = shaper.delays;
  amplitudes_ = shaper.amplitudes;
  buffer_.assign(std::bit_ceil(shaper.delays.back() + 1), initial);
  mask_ = buffer_.size() - 1;
}

std::size_t RealtimeShaper::process(std::span<const double> in, std::span<double> out) noexcept {
  const std::size_t n = std::min(in.size(), out.size());
  for (std::size_t k = 0; k < n; ++k) out[k] = step(in[k]);
  return n;
}

void RealtimeShaper::reset(double value) noexcept {
  std::fill(buffer_.begin(), buffer_.end(), value);
  head_ = 0;
}

MultiAxisShaper::MultiAxisShaper(const DiscreteShaper& shaper, std::span<const double> initial) {
  if (initial.empty()) throw core::InputError(core::at_field("axes"), "expected at least one axis");
  channels_.reserve(initial.size());
  for (const double x0 : initial) channels_.emplace_back(shaper, x0);
}

void MultiAxisShaper::step(std::span<const double> in, std::span<double> out) noexcept {
  const std::size_t n = std::min({in.size(), out.size(), channels_.size()});
  for (std::size_t i = 0; i < n; ++i) out[i] = channels_[i].step(in[i]);
}

void MultiAxisShaper::reset(std::span<const double> values) noexcept {
  const std::size_t n = std::min(values.size(), channels_.size());
  for (std::size_t i = 0; i < n; ++i) channels_[i].reset(values[i]);
}

}  // namespace servotwin::shaping
