// `servotwin capture`: run a part program on a virtual machine and write the capture CSV that a
// CNC's oscilloscope would record.
#include <chrono>

#include "command.hpp"
#include "servotwin/vcnc/machine_run.hpp"
#include "servotwin/io/capture_csv.hpp"
#include "servotwin/io/machine_json.hpp"

namespace servotwin::cli {

namespace {

struct CaptureArgs {
  std::string machine;
  ProgramSource program;
  bool ideal = false, no_u = false;
  std::uint64_t seed = 1;
  std::string output = "-";
};

int run(const CaptureArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const machine::MachineConfig machine = io::load_machine(a.machine);
  const motion::Program program = load_program(a.program, vcnc::machine_start(machine));
  vcnc::check_program_axes(program, a.program.path, machine);

  const motion::Trajectory trajectory =
      motion::interpolate(program, vcnc::limits_of(machine), vcnc::program_axes_of(machine));
  progress(global, "interpolated {} samples ({:.3f} s) in {:.1f} ms", trajectory.size(),
           static_cast<double>(trajectory.size()) * machine.ts, elapsed_ms(start));

  machine::SimulationOptions sim;
  sim.ideal = a.ideal;
  sim.seed = a.seed;
  sim.record_u = !a.no_u;
  const core::Capture capture = machine::simulate(machine, vcnc::machine_commands(machine, trajectory), sim);
  progress(global, "simulated machine '{}' ({} axes{}) in {:.1f} ms total", machine.name, machine.axes.size(),
           a.ideal ? ", ideal" : "", elapsed_ms(start));

  auto out = open_output(a.output, global);
  io::write_capture_csv(out->stream(), capture);
  out->commit();
  for (const auto& axis : capture.axes) {
    const vcnc::TrackingStats s = vcnc::tracking_stats(axis);
    progress(global, "axis {}: tracking error rms {:.2f} um, max {:.2f} um", axis.name, 1000.0 * s.rms, 1000.0 * s.max);
  }
  progress(global, "wrote {}", a.output == "-" ? "capture to stdout" : a.output);
  return kSuccess;
}

}  // namespace

void register_capture(CLI::App& app, Action& selected) {
  auto a = std::make_shared<CaptureArgs>();
  CLI::App* cmd = app.add_subcommand(
      "capture", "Run a part program on a virtual machine; write the capture CSV (t, <axis>_cmd, <axis>_act, <axis>_u)");
  cmd->add_option("-m,--machine", a->machine, "Machine preset (fadal-ppi, fadal-pid, fadal-smc, ballscrew-zpetc) or JSON file")
      ->required();
  cmd->add_option("-p,--program", a->program.path, "Part program (ISO or Heidenhain)")->required()->check(CLI::ExistingFile);
  cmd->add_flag("--ideal", a->ideal, "Switch off every nonlinearity (friction, quantization, saturation, noise, delay)");
  cmd->add_option("--seed", a->seed, "Seed of the encoder noise")->capture_default_str();
  cmd->add_flag("--no-u", a->no_u, "Do not record the control signal");
  add_program_reading_options(*cmd, a->program);
  cmd->add_option("-o,--output", a->output, "Output CSV, - for standard output")->capture_default_str();
  set_examples(*cmd,
               "  servotwin capture --machine fadal-pid --program id.nc -o capture.csv\n"
               "  servotwin capture --machine my-machine.json --program part.h --ideal -o ideal.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
