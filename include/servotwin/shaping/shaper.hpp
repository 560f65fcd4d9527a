#pragma once
/// \file
/// An input shaper: a train of impulses IS(s) = Σ A_i e^{-t_i s} convolved with a command
/// (dissertation ch. 6, catalog C6.0–C6.6). The common type of every shaper family, of the
/// discretization, of the real-time filter and of the shaper JSON file ("servotwin.shaper/1").

#include <string>
#include <vector>

namespace servotwin::shaping {

/// Impulse times (increasing, first 0) and amplitudes (summing to 1) with what they were designed
/// for. Frequencies in rad/s inside the library; `_hz` only in files and printed text.
struct Shaper {
  std::string type;               ///< family: "zv4", "zv", "zvd", "zvdd", "mzv", "ei", "2hump_ei", "3hump_ei", "multi", ...
  double omega = 0.0;             ///< design natural frequency [rad/s] (the first mode for multi-mode shapers)
  double zeta = 0.0;              ///< design damping
  std::vector<double> times;      ///< t_i [s], strictly increasing, times.front() == 0
  std::vector<double> amplitudes; ///< A_i, Σ A_i = 1

  /// t_last: the delay the shaper adds to a move [s].
  [[nodiscard]] double duration() const noexcept { return times.empty() ? 0.0 : times.back(); }
};

}  // namespace servotwin::shaping
