#pragma once
// The options `servotwin tune` and `servotwin tune compare` share: the spec (peak limits, the
// uncertainty weight) and the known HF dynamics, applied to tuning::TuneOptions.

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

#include "servotwin/tuning/tune.hpp"
#include "tune_input.hpp"

namespace servotwin::cli {

/// The spec and HF-dynamics options as given on the command line.
struct TuneSpecArgs {
  double ms = 1.5, mt = 1.5;
  std::string w2_num, w2_den, w2_from_frf;
  int w2_order = 1;
  std::optional<double> current_lag, filter, delay, ts, min_damping;
  std::string load_side = "auto";
};

/// Adds --ms, --mt, --min-damping, --load-side, --w2-num/--w2-den, --w2-from-frf, --w2-order, --current-lag, --filter, --delay
/// and --ts to `cmd`.
void add_spec_options(CLI::App& cmd, TuneSpecArgs& args);

/// Puts the spec into `options`: the peak limits, W2 (given, or fitted above the model's residuals
/// on a measured response, printed), the plant's HF dynamics overridden by the options, and the
/// sample period (the option's, else the plant description's). core::InputError names the option.
void apply_spec(const TuneSpecArgs& args, const TunePlant& plant, tuning::TuneOptions& options);

/// `--drive-filter` (repeatable): notch:auto, notch:F_HZ:WIDTH_HZ:DEPTH_DB, lowpass:F_HZ[:ZETA] or
/// biquad:FZ_HZ:ZETA_Z:FP_HZ:ZETA_P, into options.drive_filters / options.auto_notch; and
/// `--rolloff-hz F` (the lowpass case: H-infinity's roll-off, else lowpass:F). core::InputError
/// naming the option and the text at fault.
void apply_drive_filters(const std::vector<std::string>& texts, std::optional<double> rolloff_hz,
                         tuning::TuneOptions& options);

}  // namespace servotwin::cli
