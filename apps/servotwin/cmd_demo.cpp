// `servotwin demo`: the main job on the built-in default. Generates the thesis's identification
// program, interpolates it with the machine's CNC settings, captures it on the virtual machine and
// prints a summary with the true closed loop that identification has to recover.
#include <chrono>
#include <filesystem>

#include "command.hpp"
#include "servotwin/io/rapid_json.hpp"
#include "servotwin/vcnc/identification.hpp"
#include "servotwin/vcnc/machine_run.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/capture_csv.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/motion/gcode.hpp"
#include "servotwin/motion/identification_program.hpp"

namespace servotwin::cli {

namespace {

struct DemoArgs {
  std::string machine = "fadal-pid";
  std::uint64_t seed = 1;
  std::string out_dir;
};

std::string pole_summary(const std::vector<core::ModalInfo>& roots) {
  std::string out;
  for (std::size_t i = 0; i < roots.size(); ++i) {
    if (roots[i].root.imag() < 0.0) continue;  // show each conjugate pair once
    out += fmt::format("{}{:.2f} Hz/{:.2f}", out.empty() ? "" : ", ", roots[i].freq_hz, roots[i].zeta);
  }
  return out.empty() ? "none" : out;
}

void write_file(const std::filesystem::path& path, const GlobalOptions& global, const auto& writer) {
  auto out = open_output(path.string(), global);
  writer(out->stream());
  out->commit();
}

int run(const DemoArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const machine::MachineConfig machine = io::load_machine(a.machine);

  motion::IdentificationOptions id = motion::identification_defaults(motion::IdentificationSet::Standard);
  id.axes = vcnc::program_axes_of(machine);
  if (id.axes.empty()) throw core::InputError({a.machine, 0, 0, "axes"}, "the machine has no X, Y or Z axis to identify");
  id.seed = a.seed;
  for (std::size_t i = 0; i < id.axes.size(); ++i)
    id.center[static_cast<std::size_t>(id.axes[i])] = machine.axes[static_cast<std::size_t>(vcnc::machine_axis_index(machine, id.axes[i]))].home;
  const motion::Program program = motion::make_identification_program(id);

  const motion::InterpolationLimits limits = vcnc::limits_of(machine);
  const motion::Trajectory trajectory = motion::interpolate(program, limits, id.axes);
  const core::Capture capture = machine::simulate(machine, vcnc::machine_commands(machine, trajectory), {});
  const double total_ms = elapsed_ms(start);

  std::string axes_text;
  for (auto axis : id.axes) axes_text += motion::axis_letter(axis);
  fmt::print("servotwin demo: rapid identification experiment on machine '{}'\n  {}\n\n", machine.name, machine.description);
  fmt::print("1. identification program (thesis Table 3.2): {} random moves within +-{} mm on {} at F{} mm/min, seed {}: "
             "{} blocks\n",
             id.moves, id.range_mm, axes_text, id.feed_mm_min, id.seed, program.blocks.size());
  fmt::print("2. interpolation at ts = {} s, acceleration {} mm/s^2, {}{}: {} samples = {:.3f} s of motion\n", limits.ts,
             limits.accel, limits.jerk ? fmt::format("jerk {} mm/s^3", *limits.jerk) : "trapezoidal (no jerk limit)",
             limits.exact_stop_every_block ? ", exact stop after every block" : "", trajectory.size(),
             static_cast<double>(trajectory.size() - 1) * limits.ts);
  fmt::print("3. capture on the virtual machine (friction, saturation, DAC and encoder quantization on):\n");
  for (const auto& axis : capture.axes) {
    const vcnc::TrackingStats s = vcnc::tracking_stats(axis);
    fmt::print("   axis {}: tracking error rms {:.2f} um, max {:.2f} um\n", axis.name, 1000.0 * s.rms, 1000.0 * s.max);
  }
  fmt::print("4. true equivalent closed loop of each axis (thesis Eq. 3.3), what identification must recover:\n");
  for (const auto& axis : machine.axes) {
    const auto loop = machine::equivalent_closed_loop(axis, machine.ts);
    const auto& c = loop.coefficients;
    fmt::print("   axis {}: a1 {:.2f}  a2 {:.2f}  a3 {:.2f}  b0 {:.2f}  b1 {:.2f}  b2 {:.2f}  d0 {:.1f}  d1 {:.1f}{}\n",
               axis.name, c.a1, c.a2, c.a3, c.b0, c.b1, c.b2, c.d0, c.d1, loop.exact ? "" : "  (approximate)");
    fmt::print("           poles {}; zeros {}\n", pole_summary(loop.poles), pole_summary(loop.zeros));
  }
  fmt::print("\nprogram, interpolation and capture took {:.1f} ms.\n", total_ms);

  const auto identify_start = std::chrono::steady_clock::now();
  const std::vector<vcnc::NamedCapture> captures{{"demo capture", capture}};
  vcnc::IdentificationSettings settings;
  settings.shift_search = vcnc::ShiftSearch{};
  std::vector<vcnc::AxisIdentification> models;
  for (const auto& axis : capture.axes) models.push_back(vcnc::identify_axis(captures, {}, axis.name, settings));
  fmt::print("5. rapid identification (exact bounded solver, command shift searched), in {:.1f} ms:\n",
             elapsed_ms(identify_start));
  for (const auto& m : models) {
    const auto& sol = m.solution;
    const rapid::AxisModel model(sol.coefficients, m.ts);
    fmt::print("   axis {}: poles {}; {}; shift {}; simulated tracking-error fit nrmse {:.4f}\n", m.axis,
               pole_summary(model.poles()), model.is_stable() ? "stable" : "UNSTABLE", m.regressors.command_shift,
               m.fit->nrmse);
    fmt::print("           solver case {}, certified gap {:.2g}, {:.2f} ms\n", sol.kkt_case,
               sol.objective - sol.lower_bound, sol.time_ms);
  }

  if (!a.out_dir.empty()) {
    const std::filesystem::path dir(a.out_dir);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw core::InputError({a.out_dir, 0, 0, "--out"}, "cannot create the directory: " + ec.message());
    write_file(dir / "identification.nc", global, [&](std::ostream& os) { os << motion::write_iso(program); });
    write_file(dir / "capture.csv", global, [&](std::ostream& os) { io::write_capture_csv(os, capture); });
    write_file(dir / "machine.json", global, [&](std::ostream& os) { os << io::machine_to_json(machine).dump(2) << '\n'; });
    for (const auto& m : models) {
      write_file(dir / fmt::format("model_{}.json", m.axis), global,
                 [&](std::ostream& os) { os << io::axis_model_to_json(m).dump(2) << '\n'; });
    }
    fmt::print("wrote {}/identification.nc, capture.csv, machine.json and model_<axis>.json\n", a.out_dir);
  } else {
    fmt::print("(--out DIR keeps the program, the capture, the machine description and the models)\n");
  }
  return kSuccess;
}

}  // namespace

void register_demo(CLI::App& app, Action& selected) {
  auto a = std::make_shared<DemoArgs>();
  CLI::App* cmd = app.add_subcommand("demo", "Run the rapid-identification experiment on a built-in virtual machine and summarize it");
  cmd->add_option("-m,--machine", a->machine, "Machine preset or JSON file")->capture_default_str();
  cmd->add_option("--seed", a->seed, "Seed of the identification program")->capture_default_str();
  cmd->add_option("--out", a->out_dir, "Directory to keep identification.nc, capture.csv and machine.json in");
  set_examples(*cmd, "  servotwin demo\n  servotwin demo --machine fadal-ppi --out demo-run\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
