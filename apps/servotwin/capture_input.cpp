#include "capture_input.hpp"

#include <cmath>
#include <sstream>

#include "servotwin/core/error.hpp"
#include "servotwin/io/linuxcnc_config.hpp"

namespace servotwin::cli {

namespace {

io::TraceFormat format_named(const std::string& name) {
  for (const io::TraceFormat f : {io::TraceFormat::Csv, io::TraceFormat::Halsampler, io::TraceFormat::Halscope})
    if (name == io::trace_format_name(f)) return f;
  throw core::InputError({"", 0, 0, "--format"}, "expected csv, halsampler or halscope, got '" + name + "'");
}

std::vector<std::string> split_names(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream in(text);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (name.empty()) throw core::InputError({"", 0, 0, "--columns"}, "empty name in '" + text + "' (names separated by commas)");
    names.push_back(name);
  }
  return names;
}

/// Columns from the HAL file's sampler pins and the period of its thread from the INI.
void apply_linuxcnc_config(const CaptureInput& input, io::CaptureReadOptions& r) {
  std::optional<io::LinuxCncIni> ini;
  if (!input.ini.empty()) ini = io::read_linuxcnc_ini(input.ini);
  if (ini) r.joint_axes = ini->joint_axes;
  std::optional<double> period;
  if (!input.hal.empty()) {
    if (!input.columns.empty())
      throw core::InputError({"", 0, 0, "--columns"}, "give the columns with --columns or --hal, not both");
    const io::HalSamplerColumns hal = io::read_hal_sampler_columns(input.hal, input.sampler, ini ? &*ini : nullptr);
    r.columns = hal.columns;
    if (input.format.empty()) r.format = io::TraceFormat::Halsampler;
    period = hal.period_s;
  }
  if (ini && !period) period = ini->servo_period_s;
  if (!period) return;
  if (input.ts_opt != nullptr && input.ts_opt->count() > 0 && std::abs(input.ts - *period) > 1e-9 * *period)
    throw core::InputError({"", 0, 0, "--ts"}, "--ts " + std::to_string(input.ts) + " disagrees with " + input.ini +
                                                   "'s period " + std::to_string(*period) + " s");
  r.ts = *period;
}

}  // namespace

void add_capture_input_options(CLI::App& command, CaptureInput& input) {
  command.add_option("--format", input.format,
                     "Layout of the capture: csv (header row; default), halsampler (LinuxCNC halsampler output: names "
                     "from --columns or --hal, period from --ts or --ini) or halscope (LinuxCNC halscope log)")
      ->check(CLI::IsMember({"csv", "halsampler", "halscope"}));
  command.add_option("--columns", input.columns,
                     "Names of a headerless file's columns in order, comma-separated, e.g. x_cmd,x_act,x_u "
                     "(halsampler's sample number not counted)");
  command.add_option("--delimiter", input.delimiter, "CSV: the character between values (default ,; 'tab' for a tab)");
  command.add_option("--hal", input.hal,
                     "LinuxCNC HAL file: the halsampler columns from its sampler pins' nets (joint command, feedback "
                     "and pid output become <axis>_cmd, _act, _u)")
      ->check(CLI::ExistingFile);
  command.add_option("--sampler", input.sampler, "With --hal: which sampler.N the trace is from")->capture_default_str();
  command.add_option("--ini", input.ini, "LinuxCNC INI file: the sample period ([EMCMOT]SERVO_PERIOD) and joint axes")
      ->check(CLI::ExistingFile);
  command.add_option("--profile", input.profile,
                     "Trace profile (servotwin.trace-profile/1, see `import --save-profile`): format, columns, map, "
                     "units, period; options given here override it")
      ->check(CLI::ExistingFile);
  command.add_option("--map", input.maps,
                     "Column of the file for one of ours: t=, <axis>_cmd=, <axis>_act=, <axis>_u= (repeatable)");
  input.scale_opt = command.add_option("--scale", input.scale, "Factor applied to positions, e.g. 1000 for metres -> mm")
                        ->capture_default_str();
  input.ts_opt = command.add_option("--ts", input.ts, "Sample period [s] for files without a time column");
  input.jitter_opt =
      command.add_option("--max-jitter", input.max_jitter,
                         "Largest accepted time-stamp deviation from the uniform grid, as a fraction of ts")
          ->capture_default_str();
}

io::TraceProfile capture_profile(const CaptureInput& input) {
  io::TraceProfile profile;
  if (!input.profile.empty()) profile = io::read_trace_profile(input.profile);
  io::CaptureReadOptions& r = profile.reading;
  if (!input.format.empty()) r.format = format_named(input.format);
  if (!input.columns.empty()) r.columns = split_names(input.columns);
  if (!input.delimiter.empty()) {
    if (input.delimiter == "tab" || input.delimiter == "\\t") {
      r.delimiter = '\t';
    } else if (input.delimiter.size() == 1 && input.delimiter != "\"") {
      r.delimiter = input.delimiter.front();
    } else {
      throw core::InputError({"", 0, 0, "--delimiter"}, "expected one character (, ; |) or 'tab', got '" + input.delimiter + "'");
    }
  }
  std::vector<std::pair<std::string, std::string>> given;
  for (const auto& m : input.maps) {
    auto mapping = io::parse_column_mapping(m);
    // One column read as two quantities (x_cmd=qm and x_act=qm) makes a capture that tracks
    // perfectly; one quantity from two columns leaves it unclear which (issue 27 §3).
    for (const auto& [ours, theirs] : given) {
      if (theirs == mapping.second)
        throw CLI::ValidationError("--map", "column '" + theirs + "' is mapped twice (" + ours + " and " + mapping.first + ")");
      if (ours == mapping.first)
        throw CLI::ValidationError("--map", ours + " is mapped twice (columns '" + theirs + "' and '" + mapping.second + "')");
    }
    given.push_back(mapping);
    r.map.push_back(std::move(mapping));
  }
  if (input.scale_opt != nullptr && input.scale_opt->count() > 0) {
    r.scale = input.scale;
    profile.units.clear();
  }
  if (input.jitter_opt != nullptr && input.jitter_opt->count() > 0) r.max_jitter = input.max_jitter;
  if (input.ts_opt != nullptr && input.ts_opt->count() > 0) r.ts = input.ts;
  apply_linuxcnc_config(input, r);
  return profile;
}

io::CaptureReadOptions capture_read_options(const CaptureInput& input) { return capture_profile(input).reading; }

std::vector<vcnc::NamedCapture> read_captures(const std::vector<std::string>& paths, const CaptureInput& input,
                                              const CaptureSelection& selection) {
  io::CaptureReadOptions options = capture_read_options(input);
  options.axes = selection.axes;
  options.read_drive_output = selection.drive_output;
  std::vector<vcnc::NamedCapture> captures;
  for (const auto& path : paths) captures.push_back({path, io::read_capture_file(path, options)});
  return captures;
}

}  // namespace servotwin::cli
