// `servotwin interpolate`: part program -> commanded trajectory CSV.
#include <chrono>

#include "command.hpp"
#include "interpolation_options.hpp"
#include "servotwin/io/trajectory_csv.hpp"

namespace servotwin::cli {

namespace {

struct InterpolateArgs {
  ProgramSource program;
  InterpolationInput interpolation;
  std::vector<std::string> axes;
  std::string output = "-";
};

int run(const InterpolateArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const auto [limits, home] = resolve_interpolation(a.interpolation);
  const motion::Program program = load_program(a.program, home);
  const std::vector<motion::Axis> axes = parse_axes(a.axes, "--axes");
  motion::Trajectory trajectory;
  try {
    trajectory = motion::interpolate(program, limits, axes);
  } catch (const core::InputError& e) {
    rethrow_interpolation_error(e, a.interpolation);
    throw;
  }

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
  add_interpolation_options(*cmd, a->interpolation, true);
  cmd->add_option("--axes", a->axes, "Axes to write, e.g. XY (default: the axes the program uses)");
  add_program_reading_options(*cmd, a->program);
  cmd->add_option("-o,--output", a->output, "Output CSV, - for standard output")->capture_default_str();
  set_examples(*cmd,
               "  servotwin interpolate --program id.nc --ts 0.001 --accel 2000 -o trajectory.csv\n"
               "  servotwin interpolate --program part.nc --machine fadal-pid --jerk 50000 -o part.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
