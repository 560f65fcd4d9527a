#pragma once
// Options shared by the commands that read capture CSVs: column map, unit scale, period, jitter.

#include <string>
#include <vector>

#include "command.hpp"
#include "servotwin/vcnc/identification.hpp"
#include "servotwin/io/capture_csv.hpp"

namespace servotwin::cli {

struct CaptureInput {
  std::vector<std::string> maps;
  double scale = 1.0;
  double ts = 0.0;
  double max_jitter = 0.01;
  CLI::Option* ts_opt = nullptr;
};

/// Adds --map, --scale, --ts and --max-jitter.
void add_capture_input_options(CLI::App& command, CaptureInput& input);
/// Reader options from the parsed values.
io::CaptureReadOptions capture_read_options(const CaptureInput& input);
/// Reads every file with the same options.
std::vector<vcnc::NamedCapture> read_captures(const std::vector<std::string>& paths, const CaptureInput& input);

}  // namespace servotwin::cli
