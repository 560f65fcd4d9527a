// `servotwin simulate`: a tuned controller (servotwin.controller/1) closed around a simulated
// flexible plant with its nonlinearities, a setpoint or load-torque step, beside the same loop on the
// plant's linear part; writes the samples as CSV and the comparison as a report. On a flexible-frame
// plant, --test frame-sequence runs C7.19's setpoint / load-force / stator-force test instead.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "command.hpp"
#include "report_output.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/controller_json.hpp"
#include "servotwin/io/drive_simulation_csv.hpp"
#include "servotwin/io/frame_sequence_csv.hpp"
#include "servotwin/io/plant_json.hpp"
#include "servotwin/io/plant_model_json.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/report/drive_report.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"
#include "servotwin/vcnc/frame_sequence.hpp"
#include "servotwin/vcnc/plant_realization.hpp"

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
  double load_force = 0.1, stator_force = 0.1;  // frame-sequence only
  std::string shaper;                          // frame-sequence only
  std::optional<double> ts;                    // a plant realized from a fitted model
};

/// A fitted plant model (servotwin.plant-model/1) as a simulated plant: the two-mass realization
/// when the controller needs the load side, else the exact transfer function; at --ts, else at
/// the controller's discrete period.
machine::PlantConfig realized_model(const SimulateArgs& a, const io::LoadedController& loaded, const std::string& path) {
  const fit::PlantModel model = io::load_plant_model(path).model;
  const tuning::Structure s = loaded.controller.structure;
  const bool load_side = tuning::measures_load(s) || tuning::measures_both(s);
  double ts = 0.0;
  if (a.ts) ts = *a.ts;
  else if (loaded.controller.discrete) ts = loaded.controller.discrete->ts;
  else
    throw core::InputError(core::at_field("--ts"),
                           "the plant is a fitted model (" + path + "): give the sample period to simulate it at (the "
                           "controller has no discrete form; tune with --ts to give it one), or a plant description "
                           "with --plant");
  try {
    machine::PlantConfig plant = vcnc::realize_plant_model(
        model, load_side ? vcnc::Realization::kTwoMass : vcnc::Realization::kTransferFunction, ts);
    plant.name = path;
    return plant;
  } catch (const core::InputError& e) {
    if (e.where().field == "ts") throw core::InputError(core::at_field("--ts"), e.reason());
    throw core::InputError({path, 0, 0, "model"}, e.reason());
  }
}

/// The plant to run: --plant, else the plant description the controller was tuned from.
machine::PlantConfig plant_to_run(const SimulateArgs& a, const io::LoadedController& loaded, std::string& source) {
  source = a.plant.empty() ? loaded.plant_source : a.plant;
  if (io::is_plant_model_file(source)) return realized_model(a, loaded, source);
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
    rethrow_as_option(e, {{"amplitude", "--amplitude"},
                          {"duration_s", "--duration"},
                          {"torque_limit", "--torque-limit"},
                          {"settling_band", "--band"}});
    const std::string& field = e.where().field;
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
             tuning::controls_position(sim.structure) ? "position" : "velocity");
  print_metrics("plant", sim.metrics, sim.test);
  print_metrics("linear", sim.linear_metrics, sim.test);
  for (const std::string& n : sim.notes) fmt::print("note: {}\n", n);
}

// ---- the flexible-frame test (C7.19) ----

vcnc::FrameSequenceSettings frame_settings(const SimulateArgs& a, double ts) {
  vcnc::FrameSequenceSettings s;
  s.ts = ts;
  s.setpoint = a.amplitude;
  s.load_force = a.load_force;
  s.stator_force = a.stator_force;
  if (a.duration > 0.0) {  // the dissertation's thirds: 15, 30, 45 s by default
    s.duration = a.duration;
    s.load_step_time = a.duration / 3.0;
    s.stator_step_time = 2.0 * a.duration / 3.0;
    s.residual_window = std::min(s.residual_window, s.load_step_time / 3.0);
  }
  if (!a.shaper.empty()) {
    const io::LoadedShaper loaded = io::load_shaper(a.shaper);
    s.shaper_times = loaded.shaper.times;
    s.shaper_amplitudes = loaded.shaper.amplitudes;
  }
  return s;
}

/// simulate_frame_sequence with its errors named by the options.
vcnc::FrameSequence run_frame(const machine::FlexibleFrame& frame, const tuning::Controller& controller,
                              const vcnc::FrameSequenceSettings& s) {
  try {
    return vcnc::simulate_frame_sequence(frame, tuning::controller_state_space(controller), s);
  } catch (const core::InputError& e) {
    rethrow_as_option(e, {{"setpoint", "--amplitude"},
                          {"load_force", "--load-force"},
                          {"stator_force", "--stator-force"},
                          {"duration", "--duration"},
                          {"residual_window", "--duration"},
                          {"controller", "--controller"}});
    if (e.where().field.rfind("shaper", 0) == 0) throw core::InputError(core::at_field("--shaper"), e.reason());
    throw;
  } catch (const std::domain_error& e) {
    throw core::InputError(core::at_field("--controller"), e.what());
  }
}

void print_frame_sequence(const vcnc::FrameSequence& run, const vcnc::FrameSequenceSettings& s,
                          const std::string& structure, const std::string& plant_source) {
  fmt::print("frame-sequence test, {} controller on {} (ts = {:.4g} s, {} samples): setpoint {:.4g} at 0 s{}, load "
             "force {:.4g} at {:.4g} s, stator force {:.4g} at {:.4g} s\n",
             structure, plant_source, run.ts, run.time.size(), s.setpoint,
             s.shaper_times.empty() ? std::string()
                                    : fmt::format(" through a {}-impulse shaper ({:.4g} s)", s.shaper_times.size(),
                                                  s.shaper_times.back()),
             s.load_force, s.load_step_time, s.stator_force, s.stator_step_time);
  fmt::print("  {:<13} {:>12} {:>16} {:>15} {:>17}\n", "phase", "peak stator", "residual stator", "residual rotor",
             "rotor peak error");
  for (const vcnc::FramePhase& p : run.phases)
    fmt::print("  {:<13} {:>12.4g} {:>16.4g} {:>15.4g} {:>17.4g}\n", p.name, p.peak_stator, p.residual_stator,
               p.residual_rotor, p.peak_rotor_error);
  fmt::print("  (residuals: RMS over the last {:.3g} s of each phase; rotor peak error: overshoot in the setpoint "
             "phase)\n",
             s.residual_window);
  fmt::print("lightly damped closed-loop modes (damping < 0.3), amplitude each event leaves in the stator / rotor "
             "velocity (setpoint, load force, stator force):\n");
  for (std::size_t i = 0; i < run.phases[0].modes.size(); ++i) {
    const vcnc::FrameMode& m = run.phases[0].modes[i];
    if (m.damping >= 0.3) continue;
    fmt::print("  {:8.4g} rad/s ({:.4g} Hz), damping {:.3g}: stator", std::abs(m.pole), std::abs(m.pole) / kTwoPi,
               m.damping);
    for (const vcnc::FramePhase& p : run.phases) fmt::print(" {:.3g}", p.modes[i].stator);
    fmt::print(", rotor");
    for (const vcnc::FramePhase& p : run.phases) fmt::print(" {:.3g}", p.modes[i].rotor);
    fmt::print("\n");
  }
}

int run_frame_sequence(const SimulateArgs& a, const GlobalOptions& global, const io::LoadedController& loaded,
                       const machine::PlantConfig& plant, const std::string& plant_source,
                       std::chrono::steady_clock::time_point start) {
  if (!plant.frame)
    throw core::InputError(core::at_field("--test"), "frame-sequence needs a flexible-frame plant (type flexible-frame "
                                                     "or the preset c7.19-frame); " + plant_source + " is not one");
  if (tuning::controls_position(loaded.controller.structure))
    throw core::InputError(core::at_field("--test"), "frame-sequence is a velocity-loop test; this controller closes a "
                                                     "position loop");
  if (!a.report.empty())
    throw core::InputError(core::at_field("--report"), "not available for the frame-sequence test (use -o for the CSV)");
  const vcnc::FrameSequenceSettings s = frame_settings(a, plant.settings.ts);
  auto out = a.out.empty() ? nullptr : open_output(a.out, global);
  const vcnc::FrameSequence run = run_frame(*plant.frame, loaded.controller, s);
  print_frame_sequence(run, s, tuning::to_string(loaded.controller.structure), plant_source);
  if (out) {
    io::write_frame_sequence_csv(out->stream(), run, s);
    out->commit();
    progress(global, "wrote {} ({} samples, {:.0f} ms)", a.out, run.time.size(), elapsed_ms(start));
  }
  return kSuccess;
}

int run(const SimulateArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const io::LoadedController loaded = io::load_controller(a.controller);
  std::string plant_source;
  const machine::PlantConfig plant = plant_to_run(a, loaded, plant_source);
  if (a.test == "frame-sequence") return run_frame_sequence(a, global, loaded, plant, plant_source, start);
  if (!a.shaper.empty()) throw core::InputError(core::at_field("--shaper"), "only for --test frame-sequence");
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
  cmd->add_option("--ts", a->ts,
                  "Sample period [s] of a plant realized from a fitted model (servotwin.plant-model/1; default: the "
                  "controller's discrete period)")
      ->check(positive_number());
  cmd->add_option("--plant", a->plant,
                  "Plant description (servotwin.plant/1) or flexible preset name; default: the plant the controller "
                  "was tuned from, when that was a description or preset");
  cmd->add_option("--test", a->test,
                  "step: setpoint step (velocity; position for pi+p); load-step: load-torque step; frame-sequence: "
                  "C7.19's setpoint, load-force and stator-force steps on a flexible-frame plant (linear)")
      ->check(CLI::IsMember({"step", "load-step", "frame-sequence"}))
      ->capture_default_str();
  cmd->add_option("--load-force", a->load_force, "frame-sequence: the load-force step")->capture_default_str();
  cmd->add_option("--stator-force", a->stator_force, "frame-sequence: the stator-force step")->capture_default_str();
  cmd->add_option("--shaper", a->shaper, "frame-sequence: shape the setpoint with this shaper (servotwin.shaper/1)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--amplitude", a->amplitude, "Step height in plant units (rad/s, rad or N m)")->capture_default_str();
  cmd->add_option("--duration", a->duration,
                  "Simulated time [s]; 0: from the design's settling horizon (frame-sequence: 45 s, steps at the thirds)")
      ->capture_default_str();
  cmd->add_option("--torque-limit", a->torque_limit, "Limit of the torque command (anti-windup by conditional integration)");
  cmd->add_option("--band", a->band, "Settling band relative to the step")->capture_default_str();
  add_output_file_option(*cmd, a->out, "Write the samples (CSV; - for stdout)");
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin tune motor-bench -o pi.json && servotwin simulate --controller pi.json -o step.csv\n"
               "  servotwin simulate --plant plant.json --controller pi.json --test load-step --amplitude 0.5 -o load.csv\n"
               "  servotwin simulate --controller pi.json --torque-limit 2 --report step.html\n"
               "  servotwin tune c7.19-frame --structure hinf --min-damping 0.15 -o h.json && "
               "servotwin simulate --controller h.json --test frame-sequence -o frame.csv\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
