// `servotwin tune compare PLANT [--structures pi,pid,lqg] [spec options] [--report compare.html]`:
// every structure tuned to the same spec (catalog C7.15), a table on stdout, the designs run on a
// plant description with its nonlinearities, an interactive report.
#include "tune_compare.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "report_output.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/report/tuning_report.hpp"
#include "servotwin/tuning/compare.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"
#include "tune_input.hpp"
#include "tune_options.hpp"

namespace servotwin::cli {

namespace {

struct TuneCompareArgs {
  std::string plant;
  std::string structures = "pi,pid,lqg,hinf";
  std::string target_r = "2";
  TuneSpecArgs spec;
  std::string report;
};

std::vector<tuning::Structure> parse_structures(const std::string& text) {
  std::vector<tuning::Structure> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string name = text.substr(start, end - start);
    const auto s = tuning::structure_from_string(name);
    if (!s || tuning::controls_position(*s) || tuning::measures_load(*s))
      throw core::InputError(core::at_field("--structures"),
                             "expected a comma-separated list of pi, pid, lqg, hinf, got \"" + name + "\"");
    out.push_back(*s);
    start = end + 1;
  }
  return out;
}

std::string comparison_cell(double v, const char* format = "{:.4g}") { return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : "-"; }
std::string times_pi(double v) { return std::isfinite(v) ? fmt::format("x{:.2f}", v) : "-"; }

void print_comparison(const std::vector<tuning::StructureComparison>& comparison) {
  using tuning::LoopIndices;
  const auto& plant = std::find_if(comparison.begin(), comparison.end(), [](const auto& c) { return c.result.has_value(); })
                          ->result->plant;
  const double hz = plant.omega_z / kTwoPi;
  // Without a load side (higher modes, or no two-mass realization) every design is specified and
  // compared on the motor: say so in the header rather than label a motor bandwidth "load".
  const bool any_load = std::any_of(comparison.begin(), comparison.end(), [](const auto& c) {
    return c.result && !std::isnan(c.result->controller.predicted.bandwidth_load);
  });
  fmt::print("plant: antiresonance {:.4g} Hz, r = {:.4g}; spec: largest {} bandwidth with ||S|| <= Ms and tracking "
             "peak <= Mt (C7.15)\n",
             hz, plant.r, any_load ? "load" : "motor (no load side)");
  fmt::print("{:<6} {:>16} {:>12} {:>7} {:>7} {:>8} {:>11} {:>7} {:>9} {:>7} {:>9} {:>8}  {}\n", "", "design",
             any_load ? "load bw [Hz]" : "motor bw [Hz]", "vs PI", "||S||", "tracking", "||wl/Tl||", "vs PI", "ITAE",
             "vs PI", "phase m.", "damping", "controller");
  for (const tuning::StructureComparison& c : comparison) {
    const std::string name = tuning::to_string(c.structure);
    if (!c.result) {
      fmt::print("{:<6} not tuned: {}\n", name, c.failure);
      continue;
    }
    const tuning::Controller& k = c.result->controller;
    const LoopIndices& i = k.predicted;
    const bool load = !std::isnan(i.bandwidth_load);
    const double bw = load ? i.bandwidth_load : i.bandwidth_motor;
    const std::string design = k.full_order && k.full_order->hinf ? fmt::format("w0S/wz {:.4g}", k.full_order->hinf->omega_0s)
                               : k.full_order ? fmt::format("kbw {:.4g}", k.full_order->weights.kbw)
                                              : fmt::format("w*/wz {:.4g}", k.design.omega_star);
    const double velocity_per_torque = 1.0 / (plant.motor_inertia * plant.omega_z);
    fmt::print("{:<6} {:>16} {:>12} {:>7} {:>7} {:>8} {:>11} {:>7} {:>9} {:>7} {:>9} {:>8}  {}\n", name, design,
               comparison_cell(bw * hz),
               times_pi(tuning::relative_to_pi(comparison, load ? &LoopIndices::bandwidth_load : &LoopIndices::bandwidth_motor, bw)),
               comparison_cell(i.peak_s, "{:.3g}"), comparison_cell(load ? i.peak_tl : i.peak_tm, "{:.3g}"),
               comparison_cell(i.peak_load_disturbance * velocity_per_torque),
               times_pi(tuning::relative_to_pi(comparison, &LoopIndices::peak_load_disturbance, i.peak_load_disturbance)),
               comparison_cell(i.itae_load_step), times_pi(tuning::relative_to_pi(comparison, &LoopIndices::itae_load_step, i.itae_load_step)),
               comparison_cell(i.phase_margin_deg, "{:.3g}"), comparison_cell(i.min_damping, "{:.3g}"),
               k.full_order && !k.full_order->controller_stable ? "UNSTABLE compensator" : "stable");
  }
  for (const std::string& note : tuning::comparison_notes(comparison)) fmt::print("note: {}\n", note);
}

/// Every design run on the plant description with its nonlinearities: a unit setpoint step, then a
/// load step of the same height for all (the first design's linear peak torque of its step, so the
/// torque level fits the plant's units). Printed as one table; a run that cannot be made is a note.
std::vector<vcnc::DriveSimulation> simulate_on_plant(const TunePlant& plant,
                                                     const std::vector<tuning::StructureComparison>& comparison) {
  std::vector<vcnc::DriveSimulation> runs;
  if (!plant.description) return runs;
  fmt::print("on the plant with its nonlinearities (plant / linear part):\n");
  fmt::print("{:<6} {:>21} {:>23} {:>12} | {:>19} {:>23}\n", "", "step overshoot [%]", "settling", "final error",
             "load-step peak dev.", "recovery");
  std::optional<double> load_torque;
  for (const tuning::StructureComparison& c : comparison) {
    if (!c.result) continue;
    const std::string name = tuning::to_string(c.structure);
    try {
      const vcnc::DriveSimulation step = vcnc::simulate_drive(*plant.description, c.result->controller);
      const vcnc::DriveMetrics &m = step.metrics, &l = step.linear_metrics;
      const std::string step_cells =
          fmt::format("{:<6} {:>10.1f} / {:>8.1f} {:>11} / {:>9} {:>12.3g} |", name, 100.0 * m.overshoot,
                      100.0 * l.overshoot, time_or_never(m.settling_time), time_or_never(l.settling_time), m.final_error);
      if (!vcnc::has_load_torque_input(*plant.description)) {
        fmt::print("{} {:>19}\n", step_cells, "n/a (no load input)");
        runs.push_back(step);
        continue;
      }
      if (!load_torque) load_torque = step.linear_metrics.peak_torque;
      vcnc::DriveSimulationSettings settings;
      settings.test = vcnc::DriveTest::kLoadStep;
      settings.amplitude = *load_torque;
      const vcnc::DriveSimulation load = vcnc::simulate_drive(*plant.description, c.result->controller, settings);
      const vcnc::DriveMetrics &ml = load.metrics, &ll = load.linear_metrics;
      fmt::print("{} {:>9.4g} / {:>7.4g} {:>11} / {:>9}\n", step_cells, ml.peak_deviation, ll.peak_deviation,
                 time_or_never(ml.recovery_time), time_or_never(ll.recovery_time));
      runs.push_back(step);
      runs.push_back(load);
    } catch (const core::InputError& e) {
      fmt::print("{:<6} not simulated: {}\n", name, e.what());
    }
  }
  if (load_torque) fmt::print("(load step: {:.4g} N m for every structure)\n", *load_torque);
  return runs;
}

int run_tune_compare(const TuneCompareArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const TunePlant plant = load_tune_plant(a.plant);
  const auto report_file = open_report(a.report, global);
  tuning::TuneOptions options;
  options.target_r = parse_auto(a.target_r, "--target-r", false, "a resonance ratio > 1");
  apply_spec(a.spec, plant, options);
  const std::vector<tuning::Structure> structures = parse_structures(a.structures);
  const std::vector<tuning::StructureComparison> comparison = tuning::compare_structures(plant.model, options, structures);
  progress(global, "tuned {} structures ({:.0f} ms)", comparison.size(), elapsed_ms(start));
  print_comparison(comparison);
  std::vector<vcnc::DriveSimulation> runs = simulate_on_plant(plant, comparison);
  if (report_file) {
    report::ComparisonReportOptions report_options;
    report_options.source = a.plant;
    report_options.simulations = std::move(runs);
    write_report(report::comparison_report(comparison, report_options), *report_file, global);
  }
  return kSuccess;
}

}  // namespace

void add_tune_compare(CLI::App& tune, Action& selected) {
  auto a = std::make_shared<TuneCompareArgs>();
  CLI::App* cmd = tune.add_subcommand(
      "compare", "Tune PI, PID and LQG to the same spec on one plant and compare them (catalog C7.15)");
  cmd->add_option("plant", a->plant,
                  "Plant: a fitted model (servotwin.plant-model/1), a plant description (servotwin.plant/1) or a "
                  "flexible preset name")
      ->required();
  cmd->add_option("--structures", a->structures, "Comma-separated structures to compare (pi, pid, lqg, hinf)")
      ->capture_default_str();
  cmd->add_option("--target-r", a->target_r, "PID: virtual resonance ratio r-bar (C7.15 uses 2), or auto (the largest bandwidth between 2 "
                  "and 0.9 r)")->capture_default_str();
  add_spec_options(*cmd, a->spec);
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin tune compare table-5.1\n"
               "  servotwin tune compare plant_model.json --delay 0.0005 --report compare.html\n"
               "  servotwin tune compare motor-bench --structures pi,lqg --ms 1.6 --mt 1.3\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run_tune_compare(*a, g); }; });
}

}  // namespace servotwin::cli
