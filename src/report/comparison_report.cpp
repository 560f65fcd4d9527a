// The structure comparison of catalog C7.15 as a report (tuning_report.hpp comparison_report).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "number_format.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/report/tuning_report.hpp"
#include "servotwin/tuning/velocity_loop.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"
#include "chart_helpers.hpp"

namespace servotwin::report {

namespace {

using Complex = std::complex<double>;
using detail::db_of;
using detail::flat;
using detail::frequency_chart;
using detail::scaled;
using detail::time_grid;
using detail::TimeGrid;
using tuning::LoopIndices;
using tuning::StructureComparison;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr std::size_t kMinPoints = 16;
/// The charts span this factor below the lowest and above the highest plant frequency.
constexpr double kFactorBelow = 100.0;
constexpr double kFactorAbove = 20.0;

std::string num(double v, int digits = 4) { return detail::format_number(v, digits); }

/// A ratio to the PI, "-" when undefined.
std::string ratio(double v) { return std::isfinite(v) ? "×" + num(v, 3) : "-"; }

/// The designs of the comparison with their loops (normalized) and the shared scales.
struct Designed {
  const StructureComparison& entry;
  const tuning::TuneResult& result;
  tuning::VelocityLoop loop;
};

struct Context {
  const std::vector<StructureComparison>& comparison;
  const ComparisonReportOptions& options;
  const tuning::NormalizedPlant& plant;  ///< of the first design (the same plant for all)
  std::vector<Designed> designs;
  std::vector<double> omega, hz;

  [[nodiscard]] double to_seconds(double t) const { return t / plant.omega_z; }
  [[nodiscard]] double velocity_per_torque() const { return 1.0 / (plant.motor_inertia * plant.omega_z); }
  [[nodiscard]] double torque_per_velocity() const { return plant.motor_inertia * plant.omega_z; }
};

std::string label(const StructureComparison& c) { return tuning::to_string(c.structure); }

std::vector<double> frequency_grid(const tuning::NormalizedPlant& p, std::size_t points) {
  double top = p.r;
  for (const fit::Mode& m : p.higher_modes) top = std::max(top, m.resonance.omega_rad_s);
  std::vector<double> grid = core::log_space(1.0 / kFactorBelow, kFactorAbove * top, points);
  grid.push_back(1.0);
  grid.push_back(p.r);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  return grid;
}

/// What the design chose: ω* for the pole-placement structures, kbw for the LQG, ω0S for H∞.
std::string design_parameter(const tuning::Controller& c) {
  if (c.full_order && c.full_order->hinf)
    return fmt::format("ω0S/ωz = {}, γ = {}", num(c.full_order->hinf->omega_0s, 4), num(c.full_order->hinf->gamma, 4));
  if (c.full_order) return fmt::format("kbw = {}", num(c.full_order->weights.kbw, 4));
  return fmt::format("ω*/ωz = {}", num(c.design.omega_star, 4));
}

std::string controller_stability(const tuning::Controller& c) {
  if (!c.full_order) return "stable";
  return c.full_order->controller_stable ? "stable" : "UNSTABLE";
}

Table comparison_table(const Context& c) {
  Table t;
  t.title = "Structures tuned to the same spec";
  const bool any_load = std::any_of(c.comparison.begin(), c.comparison.end(), [](const StructureComparison& e) {
    return e.result && !std::isnan(e.result->controller.predicted.bandwidth_load);
  });
  t.header = {"structure",
              "design",
              any_load ? "load bandwidth [Hz]" : "motor bandwidth [Hz] (no load side)",
              "vs PI",
              "‖S‖∞",
              "tracking peak",
              "‖ωl/Tl‖∞ [model units]",
              "vs PI",
              "ITAE load step",
              "vs PI",
              "phase margin [°]",
              "modulus margin",
              "least damping",
              "controller"};
  const double hz = c.plant.omega_z / kTwoPi;
  for (const StructureComparison& e : c.comparison) {
    if (!e.result) {
      t.rows.push_back({label(e), "not tuned: " + e.failure});
      continue;
    }
    const tuning::Controller& k = e.result->controller;
    const LoopIndices& i = k.predicted;
    const bool load = !std::isnan(i.bandwidth_load);
    const double bandwidth = load ? i.bandwidth_load : i.bandwidth_motor;
    double LoopIndices::*const bw_index = load ? &LoopIndices::bandwidth_load : &LoopIndices::bandwidth_motor;
    t.rows.push_back({label(e), design_parameter(k), num(bandwidth * hz),
                      ratio(tuning::relative_to_pi(c.comparison, bw_index, bandwidth)), num(i.peak_s, 3),
                      num(load ? i.peak_tl : i.peak_tm, 3), num(i.peak_load_disturbance * c.velocity_per_torque()),
                      ratio(tuning::relative_to_pi(c.comparison, &LoopIndices::peak_load_disturbance,
                                                   i.peak_load_disturbance)),
                      num(i.itae_load_step), ratio(tuning::relative_to_pi(c.comparison, &LoopIndices::itae_load_step,
                                                                          i.itae_load_step)),
                      num(i.phase_margin_deg, 3), num(i.modulus_margin, 3), num(i.min_damping, 3),
                      controller_stability(k)});
  }
  return t;
}

Section comparison_section(const Context& c) {
  Section s;
  s.title = "Comparison";
  const tuning::Controller& first = c.designs.front().result.controller;
  s.text = fmt::format(
      "Every structure tuned to the spec of catalog C7.15: the largest load bandwidth with ‖S‖∞ <= {} and the "
      "tracking peak ‖ωl/ω*‖∞ <= {} (‖ωm/ω*‖∞ without a load side), evaluated with the known HF dynamics. Plant: "
      "antiresonance {} Hz, r = {}. The load-disturbance peak ‖ωl/Tl‖∞ and the ITAE ∫ t |ωl| dt of a unit "
      "load-torque step (normalized time) are the dissertation's disturbance measures; ×PI is the ratio to the PI. "
      "The dissertation finds (C7.15): r < 1.3 nothing helps; r in [1.7, 2.3] all similar; r > 2.3 full order "
      "wins (PID with r̄ = 2 up to +45 %, LQG and H∞ up to +100 % bandwidth).",
      num(first.design.ms.value_or(0.0), 3), num(first.design.mt.value_or(0.0), 3), num(c.plant.omega_z / kTwoPi),
      num(c.plant.r));
  s.tables.push_back(comparison_table(c));
  return s;
}

std::vector<Complex> sampled(const std::vector<double>& omega, auto f) {
  std::vector<Complex> out(omega.size());
  for (std::size_t k = 0; k < omega.size(); ++k) out[k] = f(omega[k]);
  return out;
}

Section loop_section(const Context& c) {
  Section s;
  s.title = "Loop shapes";
  s.text = "Magnitudes with the known HF dynamics (the delay exact), every structure in one chart.";
  Chart tracking = frequency_chart("Tracking: load velocity per velocity reference |ωl/ω*|", "magnitude [dB]");
  Chart sensitivity = frequency_chart("Sensitivity |S|", "magnitude [dB]");
  Chart disturbance = frequency_chart("Load-torque response |ωl/Tl| (velocity per torque)", "magnitude [dB]");
  for (const Designed& d : c.designs) {
    const std::string name = label(d.entry);
    const bool load = d.loop.has_load_tracking();
    tracking.series.push_back(
        {name, c.hz, db_of(sampled(c.omega, [&](double w) { return load ? d.loop.load_tracking(w) : d.loop.motor_tracking(w); }))});
    sensitivity.series.push_back({name, c.hz, db_of(sampled(c.omega, [&](double w) { return d.loop.sensitivity(w); }))});
    if (d.loop.has_load())
      disturbance.series.push_back(
          {name, c.hz,
           db_of(sampled(c.omega, [&](double w) { return d.loop.load_from_load_torque(w); }), c.velocity_per_torque())});
  }
  const tuning::Controller& first = c.designs.front().result.controller;
  if (first.design.mt) tracking.series.push_back(flat("Mt", c.hz, 20.0 * std::log10(*first.design.mt)));
  if (first.design.ms) sensitivity.series.push_back(flat("Ms", c.hz, 20.0 * std::log10(*first.design.ms)));
  s.charts = {std::move(tracking), std::move(sensitivity)};
  if (!disturbance.series.empty()) {
    const tuning::VelocityLoop& any = c.designs.front().loop;
    disturbance.series.push_back(
        {"no control", c.hz,
         db_of(sampled(c.omega, [&](double w) { return any.open_loop_load_from_load_torque(w); }), c.velocity_per_torque())});
    s.charts.push_back(std::move(disturbance));
  }
  return s;
}

Section time_section(const Context& c) {
  Section s;
  s.title = "Time responses (linear)";
  s.text =
      "Unit steps of each LINEAR closed loop (rational transfer functions, exact zero-order hold); the setpoint "
      "step of the velocity reference and a unit load-torque step. Friction, backlash and saturation are not in "
      "these responses (servotwin simulate runs a controller on the plant with them).";
  double horizon = 0.0, step = std::numeric_limits<double>::infinity();
  for (const Designed& d : c.designs) {
    const LoopIndices& i = d.result.controller.predicted;
    if (!i.closed_loop_stable) continue;
    horizon = std::max(horizon, i.horizon);
    step = std::min(step, i.sample_time);
  }
  if (!(horizon > 0.0) || !std::isfinite(step)) {
    s.text = "No structure has a stable closed loop: no step responses.";
    return s;
  }
  const TimeGrid g = time_grid(horizon, step, c.options.time_points);
  std::vector<double> t(g.samples);
  for (std::size_t k = 0; k < g.samples; ++k) t[k] = c.to_seconds(static_cast<double>(k) * g.dt);
  Chart setpoint{"Load velocity after a unit velocity step", "time [s]", "velocity (unit step)", {}, {}, {}, false};
  Chart torque{"Torque command of the unit velocity step", "time [s]", "torque [model units]", {}, {}, {}, false};
  Chart load_step{"Load velocity after a unit load-torque step", "time [s]", "velocity [model units]", {}, {}, {}, false};
  for (const Designed& d : c.designs) {
    if (!d.result.controller.predicted.closed_loop_stable) continue;
    const tuning::ClosedLoopTransfer cl = d.loop.closed_loop();
    const std::string name = label(d.entry);
    setpoint.series.push_back(
        {name, t, core::step_response(cl.load_tracking ? *cl.load_tracking : cl.motor_tracking, g.dt, g.samples)});
    torque.series.push_back({name, t, scaled(core::step_response(cl.effort, g.dt, g.samples), c.torque_per_velocity())});
    if (cl.load_from_load_torque)
      load_step.series.push_back(
          {name, t, scaled(core::step_response(*cl.load_from_load_torque, g.dt, g.samples), c.velocity_per_torque())});
  }
  s.charts = {std::move(setpoint), std::move(torque)};
  if (!load_step.series.empty()) s.charts.push_back(std::move(load_step));
  return s;
}

std::string time_cell(double t) { return std::isfinite(t) ? num(t) : "never"; }

/// The runs of one test, every structure in one table and one chart per signal.
Section simulation_section(const std::vector<const vcnc::DriveSimulation*>& runs, vcnc::DriveTest test) {
  Section s;
  s.title = fmt::format("Simulation on the plant: {}", vcnc::to_string(test));
  const bool step = test == vcnc::DriveTest::kSetpointStep;
  s.text = fmt::format(
      "Each design discretized at the plant's sample period closes the loop around the plant with its "
      "nonlinearities (friction, backlash, quantization, noise, delay); \"linear\" is the same loop on the "
      "plant's linear part. {} of {} for every structure.",
      step ? "A setpoint step" : "A load-torque step", num(runs.front()->amplitude));
  Table t;
  t.title = "Metrics of the controlled variable";
  t.header = step ? std::vector<std::string>{"structure", "overshoot [%]", "linear", "settling [s]", "linear",
                                             "final error", "peak torque", "limit active [%]"}
                  : std::vector<std::string>{"structure", "peak deviation", "linear", "recovery [s]", "linear",
                                             "final deviation", "peak torque", "limit active [%]"};
  Chart value{step ? "Controlled variable after the setpoint step" : "Controlled variable after the load-torque step",
              "time [s]", "controlled variable [plant units]", {}, {}, {}, false};
  Chart torque{"Torque command", "time [s]", "torque [N m]", {}, {}, {}, false};
  for (const vcnc::DriveSimulation* run : runs) {
    const vcnc::DriveMetrics &m = run->metrics, &l = run->linear_metrics;
    const std::string name = tuning::to_string(run->structure);
    if (step) {
      t.rows.push_back({name, num(100.0 * m.overshoot), num(100.0 * l.overshoot), time_cell(m.settling_time),
                        time_cell(l.settling_time), num(m.final_error), num(m.peak_torque),
                        num(100.0 * m.saturated_fraction)});
    } else {
      t.rows.push_back({name, num(m.peak_deviation), num(l.peak_deviation), time_cell(m.recovery_time),
                        time_cell(l.recovery_time), num(-m.final_error), num(m.peak_torque),
                        num(100.0 * m.saturated_fraction)});
    }
    const vcnc::ControlledVariable controlled = vcnc::controlled_variable(*run);
    Series v{name, {}, {}}, u{name, {}, {}};
    for (const vcnc::DriveSample& sample : run->samples) {
      v.x.push_back(sample.t);
      v.y.push_back(controlled(sample));
      u.x.push_back(sample.t);
      u.y.push_back(sample.torque_command);
    }
    value.series.push_back(std::move(v));
    torque.series.push_back(std::move(u));
  }
  s.tables.push_back(std::move(t));
  s.charts = {std::move(value), std::move(torque)};
  return s;
}

Section notes_section(const Context& c) {
  Section s;
  s.title = "Notes";
  for (const StructureComparison& e : c.comparison) {
    if (!e.result) continue;
    for (const std::string& n : e.result->controller.notes)
      s.text += (s.text.empty() ? "" : "\n\n") + label(e) + ": " + n;
  }
  if (s.text.empty()) s.text = "No notes.";
  return s;
}

void check_options(const ComparisonReportOptions& o) { detail::check_point_counts(o.frequency_points, o.time_points, kMinPoints); }

}  // namespace

Document comparison_report(const std::vector<StructureComparison>& comparison, const ComparisonReportOptions& options) {
  check_options(options);
  const auto first = std::find_if(comparison.begin(), comparison.end(), [](const auto& e) { return e.result.has_value(); });
  if (first == comparison.end())
    throw core::InputError(core::at_field("comparison"), "expected at least one tuned structure");
  const tuning::NormalizedPlant& plant = first->result->plant;
  Context c{comparison, options, plant, {}, frequency_grid(plant, options.frequency_points), {}};
  for (double w : c.omega) c.hz.push_back(w * plant.omega_z / kTwoPi);
  for (const StructureComparison& e : comparison) {
    if (!e.result) continue;
    c.designs.push_back({e, *e.result, tuning::controller_loop(e.result->plant, e.result->controller)});
  }
  Document doc;
  doc.title = "servotwin tune compare: controller structures";
  doc.subtitle = fmt::format("{}{}antiresonance {} Hz, r = {}", options.source, options.source.empty() ? "" : ": ",
                             num(plant.omega_z / kTwoPi), num(plant.r));
  doc.sections = {comparison_section(c), loop_section(c), time_section(c)};
  for (const vcnc::DriveTest test : {vcnc::DriveTest::kSetpointStep, vcnc::DriveTest::kLoadStep}) {
    std::vector<const vcnc::DriveSimulation*> runs;
    for (const vcnc::DriveSimulation& sim : options.simulations)
      if (sim.test == test) runs.push_back(&sim);
    if (!runs.empty()) doc.sections.push_back(simulation_section(runs, test));
  }
  doc.sections.push_back(notes_section(c));
  return doc;
}

}  // namespace servotwin::report
