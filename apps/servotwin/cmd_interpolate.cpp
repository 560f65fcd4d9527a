// `servotwin interpolate`: part program -> commanded trajectory CSV.
#include <chrono>

#include "command.hpp"
#include "servotwin/vcnc/machine_run.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/io/trajectory_csv.hpp"

namespace servotwin::cli {

namespace {

struct InterpolateArgs {
  ProgramSource program;
  std::string machine;
  bool exact_stop = false;
  double ts = 0.001, accel = 2000.0, jerk = 0.0, rapid = 15000.0, max_feed = 0.0, corner = 1.0;
  std::vector<std::string> axes;
  std::string output = "-";
  CLI::Option *ts_opt = nullptr, *accel_opt = nullptr, *jerk_opt = nullptr, *rapid_opt = nullptr,
              *max_feed_opt = nullptr, *corner_opt = nullptr;
};

int run(const InterpolateArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  motion::InterpolationLimits limits;
  motion::Point home{};
  if (!a.machine.empty()) {
    const auto machine = io::load_machine(a.machine);
    limits = vcnc::limits_of(machine);
    home = vcnc::machine_start(machine);
  }
  if (a.ts_opt->count() > 0) limits.ts = a.ts;
  if (a.accel_opt->count() > 0) limits.accel = a.accel;
  if (a.jerk_opt->count() > 0) limits.jerk = a.jerk;
  if (a.rapid_opt->count() > 0) limits.rapid_feed_mm_min = a.rapid;
  if (a.max_feed_opt->count() > 0) limits.max_feed_mm_min = a.max_feed;
  if (a.corner_opt->count() > 0) limits.corner_angle_deg = a.corner;
  if (a.exact_stop) limits.exact_stop_every_block = true;

  const motion::Program program = load_program(a.program, home);
  const motion::Trajectory trajectory = motion::interpolate(program, limits, parse_axes(a.axes, "--axes"));

  auto out = open_output(a.output, global);
  io::write_trajectory_csv(out->stream(), trajectory);
  out->commit();
  progress(global, "{} samples ({:.3f} s at ts = {} s) in {:.1f} ms -> {}", trajectory.size(),
           static_cast<double>(trajectory.size() > 0 ? trajectory.size() - 1 : 0) * trajectory.ts, trajectory.ts,
           elapsed_ms(start), a.output);
  return kSuccess;
}

}  // namespace

void register_interpolate(CLI::App& app, Action& selected) {
  auto a = std::make_shared<InterpolateArgs>();
  CLI::App* cmd = app.add_subcommand("interpolate", "Interpolate a part program into the commanded trajectory (CSV: t, <axis>_cmd)");
  cmd->add_option("-p,--program", a->program.path, "Part program (ISO or Heidenhain)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-m,--machine", a->machine, "Take ts and the CNC limits from a machine preset or JSON file");
  a->ts_opt = cmd->add_option("--ts", a->ts, "Sample period [s]")->capture_default_str();
  a->accel_opt = cmd->add_option("--accel", a->accel, "Acceleration limit along the path [mm/s^2]")->capture_default_str();
  a->jerk_opt = cmd->add_option("--jerk", a->jerk, "Jerk limit [mm/s^3] (S-curve); default: none (trapezoidal)");
  a->rapid_opt = cmd->add_option("--rapid-feed", a->rapid, "Feed of G00 / F MAX moves [mm/min]")->capture_default_str();
  a->max_feed_opt = cmd->add_option("--max-feed", a->max_feed, "Cap on programmed feeds [mm/min]");
  a->corner_opt = cmd->add_option("--corner-angle", a->corner, "Exact stop where the path turns more than this [deg]")
                      ->capture_default_str();
  cmd->add_flag("--exact-stop", a->exact_stop, "Stop exactly at the end of every block (G61, no look-ahead)");
  cmd->add_option("--axes", a->axes, "Axes to write, e.g. XY (default: the axes the program uses)");
  add_program_reading_options(*cmd, a->program);
  cmd->add_option("-o,--output", a->output, "Output CSV, - for standard output")->capture_default_str();
  set_examples(*cmd,
               "  servotwin interpolate --program id.nc --ts 0.001 --accel 2000 -o trajectory.csv\n"
               "  servotwin interpolate --program part.nc --machine fadal-pid --jerk 50000 -o part.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
