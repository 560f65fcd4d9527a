#pragma once
// Interpolator limits on the command line (`interpolate`, `predict`): a machine's CNC settings
// as the base, each limit overridable.
#include <CLI/CLI.hpp>
#include <string>

#include "servotwin/core/error.hpp"
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

/// The interpolator's errors name its limits (`accel`, `corner_angle_deg`, `max_samples`): throws
/// `e` again naming the option or the machine file each came from (issue 27 §4). `ts_source`, when
/// given, is where the sample period came from instead of --ts or the machine (predict: the models
/// set it). Returns when `e` is about something else.
void rethrow_interpolation_error(const core::InputError& e, const InterpolationInput& input,
                                 const core::SourceLocation* ts_source = nullptr);

}  // namespace servotwin::cli
