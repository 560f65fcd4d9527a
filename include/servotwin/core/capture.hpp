#pragma once
/// \file
/// A capture: commanded and actual position of one or more axes sampled together at a fixed
/// period, as a CNC's oscilloscope records it (design.md "capture CSV"). Produced by the virtual
/// machine and by the CSV reader, consumed by identification.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace servotwin::core {

/// The traces of one axis. All vectors have the capture's sample count (`u` may be empty).
struct AxisTrace {
  std::string name;         ///< lower-case axis name, e.g. "x"
  std::vector<double> cmd;  ///< commanded position x_r
  std::vector<double> act;  ///< actual (measured) position x
  std::vector<double> u;    ///< control signal, optional (empty when not recorded)
};

/// Several axes sampled together on the uniform time grid t_k = t0 + k ts.
struct Capture {
  double t0 = 0.0;  ///< time of the first sample [s]
  double ts = 0.0;  ///< sample period [s]
  std::vector<AxisTrace> axes;

  /// Number of samples (0 when there are no axes).
  [[nodiscard]] std::size_t size() const noexcept { return axes.empty() ? 0 : axes.front().cmd.size(); }
  /// Time of sample k.
  [[nodiscard]] double time(std::size_t k) const noexcept { return t0 + static_cast<double>(k) * ts; }
  /// Axis by (case-insensitive) name, or nullptr.
  [[nodiscard]] const AxisTrace* find(std::string_view name) const noexcept;
  [[nodiscard]] AxisTrace* find(std::string_view name) noexcept;
};

}  // namespace servotwin::core
