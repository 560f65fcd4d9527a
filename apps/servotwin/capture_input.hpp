#pragma once
// Options shared by the commands that read captures: layout (--format, --columns, --delimiter),
// LinuxCNC configuration (--hal, --ini), a stored profile (--profile), column map, unit scale,
// period and jitter.

#include <string>
#include <vector>

#include "command.hpp"
#include "servotwin/vcnc/identification.hpp"
#include "servotwin/io/capture_csv.hpp"
#include "servotwin/io/trace_profile.hpp"

namespace servotwin::cli {

struct CaptureInput {
  std::string format, columns, delimiter, hal, ini, profile;
  int sampler = 0;
  std::vector<std::string> maps;
  double scale = 1.0;
  double ts = 0.0;
  double max_jitter = 0.01;
  CLI::Option *ts_opt = nullptr, *scale_opt = nullptr, *jitter_opt = nullptr;
};

/// Adds --format, --columns, --delimiter, --hal, --sampler, --ini, --profile, --map, --scale, --ts
/// and --max-jitter.
void add_capture_input_options(CLI::App& command, CaptureInput& input);
/// The profile the options amount to: --profile's, overridden by the options given; columns
/// from --hal and the period from --ini. core::InputError naming the option for contradictions.
io::TraceProfile capture_profile(const CaptureInput& input);
/// Reader options from the parsed values (capture_profile's).
io::CaptureReadOptions capture_read_options(const CaptureInput& input);
/// What of a capture a command uses: memory holds only that.
struct CaptureSelection {
  std::vector<std::string> axes;  ///< empty: every axis with `_cmd` and `_act`
  bool drive_output = true;       ///< the `<axis>_u` columns
};
/// Reads every file with the same options.
std::vector<vcnc::NamedCapture> read_captures(const std::vector<std::string>& paths, const CaptureInput& input,
                                              const CaptureSelection& selection = {});

}  // namespace servotwin::cli
