#pragma once
// Interpolator limits on the command line (`interpolate`, `predict`): a machine's CNC settings
// as the base, each limit overridable.
#include <CLI/CLI.hpp>
#include <string>

#include "servotwin/motion/interpolation.hpp"

namespace servotwin::cli {

struct InterpolationInput {
  std::string machine;
  bool exact_stop = false;
  double ts = 0.001, accel = 2000.0, jerk = 0.0, rapid = 15000.0, max_feed = 0.0, corner = 1.0;
  CLI::Option *ts_opt = nullptr, *accel_opt = nullptr, *jerk_opt = nullptr, *rapid_opt = nullptr,
              *max_feed_opt = nullptr, *corner_opt = nullptr;
};

/// --machine, --accel, --jerk, --rapid-feed, --max-feed, --corner-angle, --exact-stop and, when
/// `with_ts`, --ts.
void add_interpolation_options(CLI::App& command, InterpolationInput& input, bool with_ts);

/// The limits (the machine's, then the options given) and the program's start point (the
/// machine's home, else the origin).
struct ResolvedInterpolation {
  motion::InterpolationLimits limits;
  motion::Point start{};
};
ResolvedInterpolation resolve_interpolation(const InterpolationInput& input);

}  // namespace servotwin::cli
