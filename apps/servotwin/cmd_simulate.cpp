// `servotwin simulate`: a tuned controller (servotwin.controller/1) closed around a simulated
// flexible plant with its nonlinearities, a setpoint or load-torque step, beside the same loop on the
// plant's linear part; writes the samples as CSV and the comparison as a report.
#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "command.hpp"
#include "report_output.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/controller_json.hpp"
#include "servotwin/io/drive_simulation_csv.hpp"
#include "servotwin/io/plant_json.hpp"
#include "servotwin/report/drive_report.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"

namespace servotwin::cli {

namespace {

struct SimulateArgs {
  std::string plant;
  std::string controller;
  std::string test = "step";
  double amplitude = 1.0;
  double duration = 0.0;
  std::optional<double> torque_limit;
  double band = 0.02;
  std::string out;
  std::string report;
};

/// The plant to run: --plant, else the plant description the controller was tuned from.
machine::PlantConfig plant_to_run(const SimulateArgs& a, const io::LoadedController& loaded, std::string& source) {
  source = a.plant.empty() ? loaded.plant_source : a.plant;
  if (!a.plant.empty()) return io::load_plant(a.plant);
  try {
    return io::load_plant(loaded.plant_source);
  } catch (const core::InputError& e) {
    throw core::InputError(core::at_field("--plant"),
                           "give the plant to simulate: the controller was tuned from \"" + loaded.plant_source +
                               "\", which is not a plant description or preset (" + e.reason() + ")");
  }
}

vcnc::DriveSimulationSettings settings_from(const SimulateArgs& a) {
  vcnc::DriveSimulationSettings s;
  s.test = *vcnc::drive_test_from_string(a.test);
  s.amplitude = a.amplitude;
  s.duration_s = a.duration;
  s.torque_limit = a.torque_limit;
  s.settling_band = a.band;
  return s;
}

/// simulate_drive with its errors named as the user knows them: a setting by its option, a plant
/// field by the plant's source.
vcnc::DriveSimulation simulate(const machine::PlantConfig& plant, const std::string& plant_source,
                               const tuning::Controller& controller, const std::string& controller_source,
                               const vcnc::DriveSimulationSettings& settings) {
  try {
    return vcnc::simulate_drive(plant, controller, settings);
  } catch (const core::InputError& e) {
    const std::string& field = e.where().field;
    for (const auto& [name, option] : {std::pair{"amplitude", "--amplitude"}, std::pair{"duration_s", "--duration"},
                                       std::pair{"torque_limit", "--torque-limit"}, std::pair{"settling_band", "--band"}})
      if (field == name) throw core::InputError(core::at_field(option), e.reason());
    const bool controller_field = field.rfind("controller.", 0) == 0;
    throw core::InputError({controller_field ? controller_source : plant_source, 0, 0, field}, e.reason());
  }
}

/// A time or "never" for a run that did not get there.

void print_metrics(const char* label, const vcnc::DriveMetrics& m, vcnc::DriveTest test) {
  if (test == vcnc::DriveTest::kSetpointStep) {
    fmt::print("  {:<9} rise {:>10}, overshoot {:6.2f} % (motor {:6.2f} %), settling {:>10}, ITAE {:.4g}, "
               "peak torque {:.4g}, final error {:.3g}, residual p-p {:.3g}\n",
               label, time_or_never(m.rise_time), 100.0 * m.overshoot, 100.0 * m.overshoot_motor,
               time_or_never(m.settling_time), m.itae, m.peak_torque, m.final_error, m.residual_oscillation);
  } else {
    fmt::print("  {:<9} peak deviation {:.4g} (motor {:.4g}), recovery {:>10}, ITAE {:.4g}, peak torque {:.4g}, "
               "final deviation {:.3g}, residual p-p {:.3g}\n",
               label, m.peak_deviation, m.peak_deviation_motor, time_or_never(m.recovery_time), m.itae, m.peak_torque,
               0.0 - m.final_error + 0.0, m.residual_oscillation);
  }
}

void print_summary(const vcnc::DriveSimulation& sim, const std::string& plant_source) {
  fmt::print("{} test, {} controller on {} (ts = {:.4g} s, {} samples, {:.4g} s); controlled variable: {} {}\n",
             vcnc::to_string(sim.test), tuning::to_string(sim.structure), plant_source, sim.ts, sim.samples.size(),
             sim.samples.back().t, sim.load_side ? "load" : "motor",
             tuning::has_position_loop(sim.structure) ? "position" : "velocity");
  print_metrics("plant", sim.metrics, sim.test);
  print_metrics("linear", sim.linear_metrics, sim.test);
  for (const std::string& n : sim.notes) fmt::print("note: {}\n", n);
}

int run(const SimulateArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const io::LoadedController loaded = io::load_controller(a.controller);
  std::string plant_source;
  const machine::PlantConfig plant = plant_to_run(a, loaded, plant_source);
  const auto report_file = open_report(a.report, global);
  auto out = a.out.empty() ? nullptr : open_output(a.out, global);
  const vcnc::DriveSimulation sim = simulate(plant, plant_source, loaded.controller, a.controller, settings_from(a));
  print_summary(sim, plant_source);
  if (out) {
    io::write_drive_simulation_csv(out->stream(), sim);
    out->commit();
    progress(global, "wrote {} ({} samples, {:.0f} ms)", a.out, sim.samples.size(), elapsed_ms(start));
  }
  if (report_file) {
    report::DriveReportOptions options;
    options.plant_source = plant_source;
    options.controller_source = a.controller;
    write_report(report::drive_report(sim, options), *report_file, global);
  }
  return kSuccess;
}

}  // namespace

void register_simulate(CLI::App& app, Action& selected) {
  auto a = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Run a tuned controller on a simulated flexible plant with its nonlinearities (step or load step)");
  cmd->add_option("--controller", a->controller, "Controller file (servotwin.controller/1 from `servotwin tune`)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--plant", a->plant,
                  "Plant description (servotwin.plant/1) or flexible preset name; default: the plant the controller "
                  "was tuned from, when that was a description or preset");
  cmd->add_option("--test", a->test, "step: setpoint step (velocity; position for pi+p); load-step: load-torque step")
      ->check(CLI::IsMember({"step", "load-step"}))
      ->capture_default_str();
  cmd->add_option("--amplitude", a->amplitude, "Step height in plant units (rad/s, rad or N m)")->capture_default_str();
  cmd->add_option("--duration", a->duration, "Simulated time [s]; 0: from the design's settling horizon")
      ->capture_default_str();
  cmd->add_option("--torque-limit", a->torque_limit, "Limit of the torque command (anti-windup by conditional integration)");
  cmd->add_option("--band", a->band, "Settling band relative to the step")->capture_default_str();
  cmd->add_option("-o,--out", a->out, "Write the samples (CSV; - for stdout)");
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin tune motor-bench -o pi.json && servotwin simulate --controller pi.json -o step.csv\n"
               "  servotwin simulate --plant plant.json --controller pi.json --test load-step --amplitude 0.5 -o load.csv\n"
               "  servotwin simulate --controller pi.json --torque-limit 2 --report step.html\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
