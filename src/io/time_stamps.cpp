#include "time_stamps.hpp"

#include <bit>
#include <limits>

#include "servotwin/core/large_buffer.hpp"

namespace servotwin::io::detail {

namespace {

constexpr std::size_t kMaxSteps = std::size_t{std::numeric_limits<std::uint16_t>::max()} + 1;

}  // namespace

void TimeStamps::push(double t) {
  if (size_ == 0) {
    first_ = last_ = t;
    if (plain_) values_.push_back(t);
    size_ = 1;
    return;
  }
  if (!plain_) {
    const double step = t - last_;
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(step);
    std::uint16_t code = last_code_;
    bool known = size_ > 1 && bits == last_step_bits_;
    if (!known) {
      const auto it = code_of_.find(bits);
      if (it != code_of_.end()) {
        code = it->second;
        known = true;
      }
    }
    // Recovered exactly by the replay in for_each (the same addition), else the column goes plain.
    if (last_ + step != t || (!known && steps_.size() == kMaxSteps)) {
      make_plain();
    } else {
      if (!known) {
        code = static_cast<std::uint16_t>(steps_.size());
        steps_.push_back(step);
        code_of_.emplace(bits, code);
      }
      codes_.push_back(code);
      last_step_bits_ = bits;
      last_code_ = code;
    }
  }
  if (plain_) values_.push_back(t);
  last_ = t;
  ++size_;
}

void TimeStamps::reserve(std::size_t rows) {
  if (plain_) core::reserve_large(values_, rows);
  else if (rows > 0) core::reserve_large(codes_, rows - 1);
}

void TimeStamps::make_plain() {
  std::vector<double> values;
  values.reserve(std::max(size_ + 1, codes_.capacity() + 1));
  for_each([&](std::size_t, double t) { values.push_back(t); });
  values_ = std::move(values);
  plain_ = true;
  codes_ = {};
  steps_ = {};
  code_of_ = {};
}

std::size_t TimeStamps::bytes() const noexcept {
  return values_.capacity() * sizeof(double) + codes_.capacity() * sizeof(std::uint16_t) +
         steps_.capacity() * sizeof(double);
}

}  // namespace servotwin::io::detail
