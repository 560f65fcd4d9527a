// `servotwin import`: read a capture exported by a CNC or another tool (CSV with a column map and
// unit scale, LinuxCNC halsampler or halscope, a stored profile), check it (alone and against the
// program it ran), summarize it, write it in servotwin's capture format or save how it was read.
#include <algorithm>
#include <chrono>

#include "command.hpp"
#include "capture_input.hpp"
#include "servotwin/io/capture_csv.hpp"
#include "servotwin/io/trace_profile.hpp"
#include "servotwin/vcnc/machine_run.hpp"
#include "servotwin/vcnc/trace_check.hpp"

namespace servotwin::cli {

namespace {

struct ImportArgs {
  std::string input;
  CaptureInput reading;
  std::vector<std::string> axes;
  ProgramSource program;
  std::string output, save_profile, description;
};

void summarize(const core::Capture& c, const std::string& source, io::TraceFormat format) {
  fmt::print("{}: {} ({}), {} samples at ts = {} s ({:.3f} s from t = {}), {} {}, lengths in mm\n", source,
             io::trace_format_name(format), format == io::TraceFormat::Csv ? "header row" : "LinuxCNC", c.size(), c.ts,
             static_cast<double>(c.size() - 1) * c.ts, c.t0, c.axes.size(), plural(c.axes.size(), "axis", "axes"));
  for (const auto& axis : c.axes) {
    const auto [lo, hi] = std::minmax_element(axis.cmd.begin(), axis.cmd.end());
    const vcnc::TrackingStats s = vcnc::tracking_stats(axis);
    fmt::print("  {}: command {:.6g} .. {:.6g}, tracking error rms {:.6g}, max {:.6g}{}\n", axis.name, *lo, *hi, s.rms,
               s.max, axis.u.empty() ? "" : ", with control signal");
  }
}

int run(const ImportArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  io::TraceProfile profile = capture_profile(a.reading);
  io::CaptureReadOptions options = profile.reading;
  for (const auto& axis : a.axes) options.axes.push_back(axis);
  const core::Capture capture = io::read_capture_file(a.input, options);
  progress(global, "read {} in {:.1f} ms", a.input, elapsed_ms(start));
  summarize(capture, a.input, options.format);
  std::optional<motion::Program> program;
  if (!a.program.path.empty()) program = load_program(a.program);
  const vcnc::TraceCheck check = vcnc::check_trace(capture, a.input, program ? &*program : nullptr, a.program.path);
  for (const auto& w : check.warnings) fmt::print(stderr, "warning: {}\n", w);
  for (const auto& n : check.notes) fmt::print("note: {}\n", n);
  if (!a.output.empty()) {
    auto out = open_output(a.output, global);
    io::write_capture_csv(out->stream(), capture);
    out->commit();
    progress(global, "wrote {}", a.output);
  }
  if (!a.save_profile.empty()) {
    profile.description = a.description;
    if (!options.ts) profile.reading.ts = capture.ts;  // the period found, for files that do not state it
    auto out = open_output(a.save_profile, global, "--save-profile");
    io::write_trace_profile(out->stream(), profile);
    out->commit();
    progress(global, "wrote {}: read such files with --profile {}", a.save_profile, a.save_profile);
  }
  return kSuccess;
}

}  // namespace

void register_import(CLI::App& app, Action& selected) {
  auto a = std::make_shared<ImportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "import", "Read a controller's trace (CSV with a column map, LinuxCNC halsampler or halscope, a profile), check "
                "and summarize it, optionally rewrite it or save how it was read as a profile");
  cmd->add_option("capture", a->input, "Trace file")->required()->check(CLI::ExistingFile);
  add_capture_input_options(*cmd, a->reading);
  cmd->add_option("--axis", a->axes, "Axes to read (default: every <axis>_cmd/<axis>_act pair)");
  cmd->add_option("-p,--program", a->program.path,
                  "The program the trace ran: checks units, that the command follows its path, and the feed")
      ->check(CLI::ExistingFile);
  add_program_reading_options(*cmd, a->program);
  cmd->add_option("-o,--output", a->output, "Write the capture in servotwin's format (t, <axis>_cmd, <axis>_act, <axis>_u)");
  cmd->add_option("--save-profile", a->save_profile,
                  "Write the reading options in effect (format, columns, map, units, period) as a trace profile");
  cmd->add_option("--description", a->description, "With --save-profile: what the profile is for");
  set_examples(*cmd,
               "  servotwin import data/emps/DATA_EMPS.csv --map x_cmd=qg --map x_act=qm --map x_u=vir --scale 1000\n"
               "  servotwin import scope.csv --map t=time --map x_cmd=X_nominal --map x_act=X_actual -o capture.csv\n"
               "  servotwin import trace.txt --hal twin.hal --ini twin.ini --program id.ngc --dialect linuxcnc\n"
               "  servotwin import trace.txt --format halsampler --columns x_cmd,x_act,x_u --ts 0.001 \\\n"
               "      --save-profile rig.json\n"
               "  servotwin import scope.csv --format halscope --map x_cmd=joint.0.motor-pos-cmd \\\n"
               "      --map x_act=joint.0.motor-pos-fb\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
