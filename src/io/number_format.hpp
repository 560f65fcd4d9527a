#pragma once
// Private helpers of the CSV writers: time formatting and chunked output.

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <iterator>
#include <ostream>

namespace servotwin::io::detail {

/// Smallest number of decimals (at most 12) at which both t0 and ts are whole multiples of
/// 10^-d to within 1e-9 relative: ts = 0.001 prints as 0.001, 0.002, ... rather than
/// 0.0030000000000000001. Returns -1 when no such d exists (print shortest round-trip instead).
inline int time_decimals(double t0, double ts) noexcept {
  for (int d = 0; d < 12; ++d) {
    const double scale = std::pow(10.0, d);
    const auto whole = [scale](double v) {
      const double scaled = v * scale;
      return std::abs(scaled - std::round(scaled)) <= 1e-9 * std::abs(scaled);
    };
    if (whole(ts) && whole(t0)) return d;
  }
  return -1;
}

/// Appends time t with `decimals` from time_decimals (shortest round-trip when -1).
template <typename Buffer>
void append_time(Buffer& buffer, double t, int decimals) {
  if (decimals >= 0) fmt::format_to(std::back_inserter(buffer), "{:.{}f}", t, decimals);
  else fmt::format_to(std::back_inserter(buffer), "{}", t);
}

/// Writes the buffer to `out` and empties it.
template <typename Buffer>
void write_out(Buffer& buffer, std::ostream& out) {
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  buffer.clear();
}

/// Writes the buffer out once it holds more than 64 KiB, so long files stream with flat memory.
template <typename Buffer>
void write_out_when_full(Buffer& buffer, std::ostream& out) {
  if (buffer.size() > (std::size_t{1} << 16)) write_out(buffer, out);
}

}  // namespace servotwin::io::detail
