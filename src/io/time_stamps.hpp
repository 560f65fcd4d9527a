#pragma once
// A capture's time column, kept exactly in about two bytes a row.
//
// The reader checks the time stamps against a uniform grid only once the last one is known, so it
// must keep them; an hour at 1 kHz is 29 MB of doubles, a seventh of a 3-axis capture's memory.
// Consecutive stamps of a sampled trace differ by one of a few steps (the period, and its
// neighbours from decimal rounding), and for t_(k-1) <= t_k <= 2 t_(k-1) the difference is exact
// in floating point (Sterbenz's lemma), so t_k = t_(k-1) + step is recovered bit for bit. The steps
// are numbered in a dictionary; a stamp whose step does not recover it exactly, or more distinct
// steps than a 16-bit code holds, turn the column into plain doubles.

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace servotwin::io::detail {

class TimeStamps {
 public:
  void push(double t);
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] double front() const noexcept { return first_; }
  [[nodiscard]] double back() const noexcept { return last_; }
  /// Reserves room for `rows` stamps in the current representation.
  void reserve(std::size_t rows);
  /// Calls f(k, t_k) for every stamp in order.
  template <typename F>
  void for_each(F&& f) const {
    if (plain_) {
      for (std::size_t k = 0; k < values_.size(); ++k) f(k, values_[k]);
      return;
    }
    double t = first_;
    if (size_ > 0) f(0, t);
    for (std::size_t k = 1; k < size_; ++k) {
      t += steps_[codes_[k - 1]];
      f(k, t);
    }
  }
  /// Bytes held (for tests of the compact form).
  [[nodiscard]] std::size_t bytes() const noexcept;

 private:
  void make_plain();

  std::size_t size_ = 0;
  double first_ = 0.0, last_ = 0.0;
  bool plain_ = false;
  std::vector<double> values_;          ///< plain form
  std::vector<std::uint16_t> codes_;    ///< compact form: codes_[k - 1] numbers t_k - t_(k-1)
  std::vector<double> steps_;           ///< the steps by code
  std::unordered_map<std::uint64_t, std::uint16_t> code_of_;  ///< a step's bits -> its code
  std::uint64_t last_step_bits_ = 0;
  std::uint16_t last_code_ = 0;
};

}  // namespace servotwin::io::detail
