// `servotwin import`: read a capture exported by a CNC or another tool (column map, unit scale),
// check it, summarize it and write it in servotwin's capture format.
#include <algorithm>
#include <chrono>

#include "command.hpp"
#include "capture_input.hpp"
#include "servotwin/vcnc/machine_run.hpp"
#include "servotwin/io/capture_csv.hpp"

namespace servotwin::cli {

namespace {

struct ImportArgs {
  std::string input;
  CaptureInput reading;
  std::vector<std::string> axes;
  std::string output;
};

void summarize(const core::Capture& c, const std::string& source) {
  fmt::print("{}: {} samples at ts = {} s ({:.3f} s from t = {}), {} axis{}\n", source, c.size(), c.ts,
             static_cast<double>(c.size() - 1) * c.ts, c.t0, c.axes.size(), c.axes.size() == 1 ? "" : "es");
  for (const auto& axis : c.axes) {
    const auto [lo, hi] = std::minmax_element(axis.cmd.begin(), axis.cmd.end());
    const vcnc::TrackingStats s = vcnc::tracking_stats(axis);
    fmt::print("  {}: command {:.6g} .. {:.6g}, tracking error rms {:.6g}, max {:.6g}{}\n", axis.name, *lo, *hi, s.rms,
               s.max, axis.u.empty() ? "" : ", with control signal");
  }
}

int run(const ImportArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  io::CaptureReadOptions options = capture_read_options(a.reading);
  for (const auto& axis : a.axes) options.axes.push_back(axis);
  const core::Capture capture = io::read_capture_file(a.input, options);
  progress(global, "read {} in {:.1f} ms", a.input, elapsed_ms(start));
  summarize(capture, a.input);
  if (!a.output.empty()) {
    auto out = open_output(a.output, global);
    io::write_capture_csv(out->stream(), capture);
    out->commit();
    progress(global, "wrote {}", a.output);
  }
  return kSuccess;
}

}  // namespace

void register_import(CLI::App& app, Action& selected) {
  auto a = std::make_shared<ImportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "import", "Read a foreign capture CSV (column map, unit scale), check and summarize it, optionally rewrite it");
  cmd->add_option("capture", a->input, "CSV with a header row")->required()->check(CLI::ExistingFile);
  add_capture_input_options(*cmd, a->reading);
  cmd->add_option("--axis", a->axes, "Axes to read (default: every <axis>_cmd/<axis>_act pair)");
  cmd->add_option("-o,--output", a->output, "Write the capture in servotwin's format (t, <axis>_cmd, <axis>_act, <axis>_u)");
  set_examples(*cmd,
               "  servotwin import data/emps/DATA_EMPS.csv --map x_cmd=qg --map x_act=qm --map x_u=vir --scale 1000\n"
               "  servotwin import scope.csv --map t=time --map x_cmd=X_nominal --map x_act=X_actual -o capture.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
