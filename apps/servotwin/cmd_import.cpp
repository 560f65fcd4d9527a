// `servotwin import`: read a capture exported by a CNC or another tool (column map, unit scale),
// check it, summarize it and write it in servotwin's capture format.
#include <algorithm>
#include <chrono>

#include "command.hpp"
#include "pipeline.hpp"
#include "servotwin/io/capture_csv.hpp"

namespace servotwin::cli {

namespace {

struct ImportArgs {
  std::string input;
  std::vector<std::string> maps;
  double scale = 1.0;
  double ts = 0.0;
  double max_jitter = 0.01;
  std::vector<std::string> axes;
  std::string output;
  CLI::Option* ts_opt = nullptr;
};

void summarize(const core::Capture& c, const std::string& source) {
  fmt::print("{}: {} samples at ts = {} s ({:.3f} s from t = {}), {} axis{}\n", source, c.size(), c.ts,
             static_cast<double>(c.size() - 1) * c.ts, c.t0, c.axes.size(), c.axes.size() == 1 ? "" : "es");
  for (const auto& axis : c.axes) {
    const auto [lo, hi] = std::minmax_element(axis.cmd.begin(), axis.cmd.end());
    const TrackingStats s = tracking_stats(axis);
    fmt::print("  {}: command {:.6g} .. {:.6g}, tracking error rms {:.6g}, max {:.6g}{}\n", axis.name, *lo, *hi, s.rms,
               s.max, axis.u.empty() ? "" : ", with control signal");
  }
}

int run(const ImportArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  io::CaptureReadOptions options;
  for (const auto& m : a.maps) options.map.push_back(io::parse_column_mapping(m));
  options.scale = a.scale;
  options.max_jitter = a.max_jitter;
  if (a.ts_opt->count() > 0) options.ts = a.ts;
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
  cmd->add_option("--map", a->maps, "Column of the file for one of ours: t=, <axis>_cmd=, <axis>_act=, <axis>_u= (repeatable)");
  cmd->add_option("--scale", a->scale, "Factor applied to positions, e.g. 1000 for metres -> mm")->capture_default_str();
  a->ts_opt = cmd->add_option("--ts", a->ts, "Sample period [s] for files without a time column");
  cmd->add_option("--max-jitter", a->max_jitter, "Largest accepted time-stamp deviation from the uniform grid, as a fraction of ts")
      ->capture_default_str();
  cmd->add_option("--axis", a->axes, "Axes to read (default: every <axis>_cmd/<axis>_act pair)");
  cmd->add_option("-o,--output", a->output, "Write the capture in servotwin's format (t, <axis>_cmd, <axis>_act, <axis>_u)");
  set_examples(*cmd,
               "  servotwin import data/emps/DATA_EMPS.csv --map x_cmd=qg --map x_act=qm --map x_u=vir --scale 1000\n"
               "  servotwin import scope.csv --map t=time --map x_cmd=X_nominal --map x_act=X_actual -o capture.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
