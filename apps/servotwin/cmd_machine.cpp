// `servotwin machine`: describe a virtual machine and its equivalent closed loops (thesis Eq. 3.3).
#include <cmath>

#include "command.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/machine/presets.hpp"

namespace servotwin::cli {

namespace {

struct MachineArgs {
  std::string machine;
  bool json = false, export_config = false, list = false;
  std::string output = "-";
};

std::string describe_root(const nlohmann::json& r) {
  if (r["hz"].is_null()) return "z = 0 (pure delay)";
  const double zeta = r["zeta"].get<double>();
  if (std::abs(r["im"].get<double>()) > 0.0) return fmt::format("{:.2f} Hz, zeta {:.3f}", r["hz"].get<double>(), zeta);
  return fmt::format("{:.2f} Hz, real{}", r["hz"].get<double>(), zeta < 0 ? " (unstable)" : "");
}

void print_machine_roots(const char* label, const nlohmann::json& roots) {
  fmt::print("  {}:", label);
  if (roots.empty()) fmt::print(" none");
  for (std::size_t i = 0; i < roots.size(); ++i) {
    if (i > 0 && roots[i - 1]["re"] == roots[i]["re"] && roots[i - 1]["im"].get<double>() == -roots[i]["im"].get<double>())
      continue;  // second of a conjugate pair
    fmt::print(" [{}]", describe_root(roots[i]));
  }
  fmt::print("\n");
}

void print_text(const machine::MachineConfig& m, const nlohmann::json& report) {
  fmt::print("{}: {}\n  sample period {} s; CNC accel {} mm/s^2, rapid {} mm/min{}\n", m.name, m.description, m.ts,
             m.cnc.accel, m.cnc.rapid_feed_mm_min, m.cnc.jerk ? fmt::format(", jerk {} mm/s^3", *m.cnc.jerk) : "");
  for (const auto& axis : report["axes"]) {
    const auto& c = axis["closed_loop"];
    fmt::print("axis {} ({}): equivalent closed loop, {}\n", axis["name"].get<std::string>(),
               axis["controller"].get<std::string>(), axis["exact"].get<bool>() ? "exact" : "approximate");
    if (!axis["exact"].get<bool>()) fmt::print("  method: {}\n", axis["method"].get<std::string>());
    fmt::print("  a1 = {:.2f}  a2 = {:.2f}  a3 = {:.2f}\n", c["a1"].get<double>(), c["a2"].get<double>(), c["a3"].get<double>());
    fmt::print("  b0 = {:.2f}  b1 = {:.2f}  b2 = {:.2f}\n", c["b0"].get<double>(), c["b1"].get<double>(), c["b2"].get<double>());
    fmt::print("  d0 = {:.2f}  d1 = {:.2f}\n", c["d0"].get<double>(), c["d1"].get<double>());
    print_machine_roots("poles", axis["poles"]);
    print_machine_roots("zeros", axis["zeros"]);
  }
}

int run(const MachineArgs& a, const GlobalOptions& global) {
  if (a.list) {
    for (const auto& name : machine::preset_names()) fmt::print("{:16} {}\n", name, machine::preset(name).description);
    return kSuccess;
  }
  if (a.machine.empty())
    throw CLI::RequiredError("a machine preset or JSON file (or --list)");
  const machine::MachineConfig m = io::load_machine(a.machine);
  if (a.export_config) {
    auto out = open_output(a.output, global);
    out->stream() << io::machine_to_json(m).dump(2) << '\n';
    out->commit();
    return kSuccess;
  }
  const nlohmann::json report = io::closed_loop_report(m);
  if (a.json) {
    auto out = open_output(a.output, global);
    out->stream() << report.dump(2) << '\n';
    out->commit();
  } else {
    print_text(m, report);
  }
  return kSuccess;
}

}  // namespace

void register_machine(CLI::App& app, Action& selected) {
  auto a = std::make_shared<MachineArgs>();
  CLI::App* cmd = app.add_subcommand("machine", "Show a virtual machine and its equivalent closed loops (thesis Eq. 3.3)");
  cmd->add_option("machine", a->machine, "Preset name or machine JSON file");
  cmd->add_flag("--json", a->json, "Print the closed-loop report as JSON (closed_loop a1..d1, poles and zeros in Hz)");
  cmd->add_flag("--export", a->export_config, "Print the full machine description (servotwin.machine/1) to edit");
  cmd->add_flag("--list", a->list, "List the presets");
  cmd->add_option("-o,--output", a->output, "Output file for --json/--export, - for standard output")->capture_default_str();
  set_examples(*cmd,
               "  servotwin machine --list\n"
               "  servotwin machine fadal-pid\n"
               "  servotwin machine fadal-pid --json\n"
               "  servotwin machine fadal-ppi --export -o my-machine.json   # edit, then --machine my-machine.json\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
