#include "capture_input.hpp"

namespace servotwin::cli {

void add_capture_input_options(CLI::App& command, CaptureInput& input) {
  command.add_option("--map", input.maps,
                     "Column of the file for one of ours: t=, <axis>_cmd=, <axis>_act=, <axis>_u= (repeatable)");
  command.add_option("--scale", input.scale, "Factor applied to positions, e.g. 1000 for metres -> mm")
      ->capture_default_str();
  input.ts_opt = command.add_option("--ts", input.ts, "Sample period [s] for files without a time column");
  command.add_option("--max-jitter", input.max_jitter,
                     "Largest accepted time-stamp deviation from the uniform grid, as a fraction of ts")
      ->capture_default_str();
}

io::CaptureReadOptions capture_read_options(const CaptureInput& input) {
  io::CaptureReadOptions options;
  for (const auto& m : input.maps) options.map.push_back(io::parse_column_mapping(m));
  options.scale = input.scale;
  options.max_jitter = input.max_jitter;
  if (input.ts_opt != nullptr && input.ts_opt->count() > 0) options.ts = input.ts;
  return options;
}

std::vector<vcnc::NamedCapture> read_captures(const std::vector<std::string>& paths, const CaptureInput& input) {
  const io::CaptureReadOptions options = capture_read_options(input);
  std::vector<vcnc::NamedCapture> captures;
  for (const auto& path : paths) captures.push_back({path, io::read_capture_file(path, options)});
  return captures;
}

}  // namespace servotwin::cli
