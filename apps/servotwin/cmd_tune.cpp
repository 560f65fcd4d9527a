// `servotwin tune`: a cascade PI/PID (and P position loop) for a flexible drive from its fitted
// plant model, checked against the known HF dynamics, written as controller.json.
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "command.hpp"
#include "report_output.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/io/controller_json.hpp"
#include "servotwin/report/tuning_report.hpp"
#include "servotwin/tuning/tune.hpp"
#include "servotwin/tuning/uncertainty.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"
#include "tune_compare.hpp"
#include "tune_input.hpp"
#include "tune_options.hpp"

namespace servotwin::cli {

namespace {


struct TuneArgs {
  std::string plant;
  std::string structure = "pi";
  double zeta_star = 0.8;
  std::string omega_star = "auto";
  std::string kbw = "auto", kff = "auto";
  std::string omega_0s = "auto", omega_0t = "auto";
  double xi_v = 0.8;
  std::string modes = "active";
  std::optional<int> controller_order;
  std::optional<double> rolloff_hz;
  std::vector<std::string> drive_filters;
  bool raw_motor_velocity = false;
  std::optional<double> measurement_noise;
  std::string target_r = "2";
  std::optional<double> tau;
  bool allow_negative_kd = false;
  TuneSpecArgs spec;
  double setpoint_weight = 1.0;
  std::string out;
  std::string report;
};

tuning::TuneOptions options_from(const TuneArgs& a, const TunePlant& plant) {
  tuning::TuneOptions o;
  o.structure = *tuning::structure_from_string(a.structure);
  o.zeta_star = a.zeta_star;
  o.omega_star = parse_auto(a.omega_star, "--omega-star", false, "omega*/omega_z > 0");
  o.kbw = parse_auto(a.kbw, "--kbw", false, "a bandwidth knob > 0");
  o.feedforward = parse_auto(a.kff, "--kff", true, "a normalized feedforward gain >= 0");
  o.omega_0s = parse_auto(a.omega_0s, "--omega-0s", false, "w0S/omega_z > 0");
  o.omega_0t = parse_auto(a.omega_0t, "--omega-0t", false, "w0T/omega_z > 0");
  o.xi_v = a.xi_v;
  o.hinf_modes = *tuning::parse_mode_handling(a.modes);
  o.controller_order = a.controller_order;
  o.lqg.raw_motor_velocity = a.raw_motor_velocity;
  if (a.measurement_noise) {
    o.lqg.measurement_noise = *a.measurement_noise;  // the user's V is kept, not raised
    o.lqg_position.measurement_noise = *a.measurement_noise;
    o.raise_measurement_noise = false;
  }
  o.target_r = parse_auto(a.target_r, "--target-r", false, "a resonance ratio > 1");
  o.tau = a.tau;
  o.allow_negative_kd = a.allow_negative_kd;
  o.setpoint_weight = a.setpoint_weight;
  apply_spec(a.spec, plant, o);
  apply_drive_filters(a.drive_filters, a.rolloff_hz, o);
  return o;
}

/// "inf" for a margin without a crossing.
std::string margin(double v, const char* unit) {
  if (std::isinf(v)) return "inf (no crossing)";
  return fmt::format("{:.3g} {}", v, unit);
}

/// Each drive filter as a drive's menu takes it, and its biquad coefficients.
void print_drive_filters(const std::vector<tuning::DriveFilter>& filters) {
  for (std::size_t i = 0; i < filters.size(); ++i) {
    const tuning::DriveFilter& f = filters[i];
    const tuning::DriveFilterSpec& s = f.spec;
    std::string what;
    switch (s.type) {
      case tuning::DriveFilterType::kNotch:
        what = fmt::format("notch at {:.4g} Hz, width {:.4g} Hz, depth {:.3g} dB", s.frequency_hz, s.width_hz, s.depth_db);
        break;
      case tuning::DriveFilterType::kLowpass:
        what = s.damping ? fmt::format("second-order lowpass at {:.4g} Hz, damping {:.3g}", s.frequency_hz, *s.damping)
                         : fmt::format("first-order lowpass at {:.4g} Hz", s.frequency_hz);
        break;
      case tuning::DriveFilterType::kBiquad:
        what = fmt::format("biquad: numerator {:.4g} Hz / damping {:.3g}, denominator {:.4g} Hz / damping {:.3g}",
                           s.frequency_hz, *s.damping, s.pole_frequency_hz, s.pole_damping);
        break;
    }
    fmt::print("drive filter {}: {}{} (at the controller's output, designed with)\n", i + 1, what,
               s.automatic ? " [notch:auto]" : "");
    if (f.discrete)
      fmt::print("  discrete at ts = {:.4g} s (Tustin, prewarped at {:.4g} Hz): b0 b1 b2 = {:.10g} {:.10g} {:.10g}, "
                 "a1 a2 = {:.10g} {:.10g}\n",
                 f.discrete->ts, f.discrete->prewarp_hz, f.discrete->b0, f.discrete->b1, f.discrete->b2, f.discrete->a1,
                 f.discrete->a2);
  }
}

/// The pole-placement part of the summary: advice, admissible range, ω* and the gains.
void print_cascade(const tuning::TuneResult& r, double hz) {
  const tuning::Controller& c = r.controller;
  fmt::print("advice: {}\n", r.advice.verdict);
  fmt::print("admissible omega*: [{:.4g}, {:.4g}] omega_z = [{:.4g}, {:.4g}] Hz (upper end: {})\n", r.range.omega_min,
             r.range.omega_max, r.range.omega_min * hz, r.range.omega_max * hz, tuning::to_string(r.range.upper));
  fmt::print("structure {}: omega* = {:.4g} omega_z = {:.4g} Hz, zeta* = {} ({})\n", tuning::to_string(c.structure),
             c.design.omega_star, c.design.omega_star * hz, c.design.zeta_star, c.design.omega_star_source);
  const tuning::PidGains& g = c.physical;
  fmt::print("gains (model units): Kp = {:.6g}, Ki = {:.6g}", g.kp, g.ki);
  if (g.kd != 0.0) fmt::print(", Kd = {:.6g}, tau = {:.4g} s", g.kd, g.tau);
  fmt::print(", setpoint weight wp = {}\n", g.wp);
  print_drive_filters(c.drive_filters);
}

/// The P position loop of pi+p and lqg+p.
void print_position_loop(const tuning::Controller& c, double hz) {
  if (!c.kpp_physical || !c.position) return;
  fmt::print("position loop: Kpp = {:.6g} 1/s (no-overshoot limit {:.6g}{}); load-position bandwidth {:.4g} Hz, "
             "||phi_l/T_l|| = {:.3g}\n",
             *c.kpp_physical, c.position->kpp_nominal * c.plant.omega_z,
             c.position->kpp_rs ? fmt::format(", robust-stability limit {:.6g}", *c.position->kpp_rs * c.plant.omega_z) : "",
             c.position->bandwidth_load * hz, c.position->j2);
}

/// A position controller's prefilter (C7.13), in seconds.
void print_prefilter(const tuning::FullOrderSummary& f, const tuning::PlantScales& scales) {
  if (f.prefilter_tau == 0.0)
    fmt::print("reference prefilter: none needed (the load position does not overshoot without it)\n");
  else
    fmt::print("reference prefilter: 1/(tau s + 1), tau = {:.4g} s (the smallest keeping the load position free of "
               "overshoot, C7.13)\n",
               f.prefilter_tau / scales.omega_z);
}

/// The LQG part of the summary: kbw, kff and the compensator's stability.
void print_lqg(tuning::Structure structure, const tuning::FullOrderSummary& f, const tuning::PlantScales& scales) {
  if (f.position_weights) {
    fmt::print("structure {}: LQG position loop (C7.13, {} states with the prefilter): kbw = {:.4g} ({}), Kalman "
               "filter V = {:g}\n",
               tuning::to_string(structure), f.compensator.states(), f.position_weights->kbw, f.kbw_source,
               f.position_weights->measurement_noise);
    print_prefilter(f, scales);
    fmt::print("compensator: {}\n", f.controller_stable ? "stable" : "UNSTABLE (stable only inside the closed loop)");
    return;
  }
  fmt::print("structure {}: LQG velocity loop ({}, {} states): kbw = {:.4g} ({}), feedforward kff = {:.4g} "
             "normalized = {:.4g} torque per velocity ({})\n",
             tuning::to_string(structure),
             tuning::measures_both(structure) ? "C7.17, integral on the load, motor and load velocity measured" : "C7.13",
             f.compensator.states(), f.weights.kbw, f.kbw_source, f.weights.feedforward,
             f.weights.feedforward * scales.motor_inertia * scales.omega_z, f.feedforward_source);
  fmt::print("compensator: {}\n", f.controller_stable ? "stable" : "UNSTABLE (stable only inside the closed loop)");
}

/// The H-infinity part of the summary: the weights, gamma and the controller's stability.
void print_hinf(tuning::Structure structure, const tuning::FullOrderSummary& f, const tuning::PlantScales& scales) {
  const tuning::HinfSummary& h = *f.hinf;
  const double hz = scales.omega_z / kTwoPi;
  const bool position = tuning::is_position_controller(structure);
  fmt::print("structure {}: mixed-sensitivity {} loop ({}, {} states{}): w0S = {:.4g} omega_z = {:.4g} Hz "
             "({}), w0T = {:.4g} omega_z, xi_v = {}; gamma = {:.4g} (optimum {:.4g})\n",
             tuning::to_string(structure),
             position                             ? "position"
             : tuning::measures_load(structure) ? "velocity, load measured"
                                                  : "velocity",
             tuning::measures_load(structure) ? "C7.17" : "C7.14", f.compensator.states(),
             position && f.prefilter_tau > 0.0 ? " with the prefilter" : "", h.omega_0s, h.omega_0s * hz,
             h.omega_0s_source, h.omega_0t, h.xi_v, h.gamma, h.gamma_optimal);
  if (position) print_prefilter(f, scales);
  if (h.rolloff)
    fmt::print("roll-off: 1/(s/wf + 1) at the controller's output, wf = {:.4g} Hz (designed with; strictly proper)\n",
               *h.rolloff * hz);
  if (h.modes != tuning::ModeHandling::kFirstMode)
    fmt::print("higher modes: {} (C7.16)\n", h.modes == tuning::ModeHandling::kActive
                                                 ? "designed with, damped actively (V extended, eq. 7.164)"
                                                 : "designed with, cancelled by the controller (passive)");
  // The minimal realization drops only states of Hankel value <= 1e-6 of the largest, so its bound
  // 2 sum(dropped) stays below 2e-6 * (count) * largest; a larger bound means a truncation.
  const bool truncated = !h.hankel.empty() && h.reduction_error_bound > 2e-6 * static_cast<double>(h.hankel.size()) *
                                                                             h.hankel.front();
  fmt::print("controller order: {} of {} ({}); Hankel singular values of its stable part:", f.compensator.states(),
             h.full_order,
             truncated ? fmt::format("balanced truncation, ||K_full - K||inf <= {:.3g}", h.reduction_error_bound)
                       : std::string("minimal realization"));
  for (double v : h.hankel) fmt::print(" {:.3g}", v);
  fmt::print("\n");
  fmt::print("controller: {}\n", f.controller_stable ? "stable" : "UNSTABLE (stable only inside the closed loop)");
}

void print_summary(const tuning::TuneResult& r, const std::string& source) {
  const tuning::NormalizedPlant& p = r.plant;
  const tuning::Controller& c = r.controller;
  const double hz = p.omega_z / kTwoPi;
  fmt::print("{}: antiresonance {:.4g} Hz, resonance ratio r = {:.4g}, zeta_z = {:.3g}, zeta_p = {:.3g}, "
             "rigid pole a = {:.3g} omega_z, Im = {:.5g}{}\n",
             source, hz, p.r, p.zeta_z, p.zeta_p, p.a, p.motor_inertia,
             p.higher_modes.empty() ? "" : fmt::format(", {} higher {}", p.higher_modes.size(),
                                                                    plural(p.higher_modes.size(), "mode", "modes")));
  if (c.full_order && c.full_order->hinf) {
    print_hinf(c.structure, *c.full_order, c.plant);
  } else if (c.full_order) {
    print_lqg(c.structure, *c.full_order, c.plant);
  } else {
    print_cascade(r, hz);
  }
  print_position_loop(c, hz);
  const tuning::LoopIndices& i = c.predicted;
  // A position controller's indices judge positions (phi/phi*, phi_l/T_l).
  const bool position = tuning::is_position_controller(c.structure);
  fmt::print("predicted (with the known HF dynamics{}): {}\n", position ? "; positions" : "",
             i.closed_loop_stable ? "stable" : "UNSTABLE");
  fmt::print("  {}bandwidth: motor {:.4g} Hz, load {}\n", position ? "position " : "", i.bandwidth_motor * hz,
             std::isnan(i.bandwidth_load) ? std::string(p.higher_modes.empty()
                                                            ? "n/a (no two-mass realization with friction >= 0: no load side)"
                                                            : "n/a (higher modes: no load side)")
                                          : fmt::format("{:.4g} Hz", i.bandwidth_load * hz));
  if (std::isnan(i.peak_tl))
    fmt::print("  peaks: ||S|| = {:.3g}, ||T|| = {:.3g} (no load side)\n", i.peak_s, i.peak_t);
  else
    fmt::print("  peaks: ||S|| = {:.3g}, ||T|| = {:.3g}, {} = {:.3g}; J2 = {:.3g}\n", i.peak_s, i.peak_t,
               position ? "||phi_l/phi*|| (with the prefilter)" : "||wl/w*||", i.peak_tl, i.j2);
  fmt::print("  least closed-loop damping: {:.3g}{}\n", i.min_damping,
             c.design.min_damping ? fmt::format(" (required >= {:.3g})", *c.design.min_damping) : std::string());
  fmt::print("  margins: gain {}, phase {}, modulus {:.3g}\n", margin(i.gain_margin_db, "dB"),
             margin(i.phase_margin_deg, "deg"), i.modulus_margin);
  fmt::print("  {}step: overshoot {:.1f} %, 2 % settling {:.4g} s; load-step ITAE {:.4g} (normalized)\n",
             position ? "position " : "", 100.0 * i.overshoot, p.physical_time(i.settling_time), i.itae_load_step);
  if (c.robustness.rs) {
    fmt::print("  robustness: ||W2 T|| = {:.4f} (RS {}), ||S||/Ms = {:.4f}, RP {:.4f} ({})\n", *c.robustness.rs,
               *c.robustness.rs < 1.0 ? "ok" : "FAILS", *c.robustness.np, *c.robustness.rp,
               *c.robustness.rp < 1.0 ? "ok" : "fails");
  }
  if (c.robustness.rp_tracking) {
    fmt::print("  robust tracking (C7.13, worst-case ||wm/w*||/Mt): {:.4f} ({})\n", *c.robustness.rp_tracking,
               *c.robustness.rp_tracking < 1.0 ? "ok" : "fails");
  }
  if (c.discrete) {
    fmt::print("discretized at ts = {:.4g} s (Tustin{})\n", c.discrete->ts,
               c.prewarp_rad_s ? fmt::format(", prewarped at {:.4g} Hz", *c.prewarp_rad_s / kTwoPi) : "");
  }
  for (const std::string& n : c.notes) fmt::print("note: {}\n", n);
}

/// The simulated variable the numbers judge, and why when it is the motor's although a load
/// prediction was printed above.
std::string judged_variable(const vcnc::DriveSimulation& sim) {
  const vcnc::ControlledVariable v = vcnc::controlled_variable(sim);
  return fmt::format("{} {}{}", v.load ? "load" : "motor", v.position ? "position" : "velocity",
                     sim.load_side ? "" : " (this plant has no load side to simulate)");
}

void print_verification(const vcnc::DriveSimulation& sim) {
  const vcnc::DriveMetrics& m = sim.metrics;
  const vcnc::DriveMetrics& l = sim.linear_metrics;
  if (sim.test == vcnc::DriveTest::kSetpointStep) {
    fmt::print("  step of {:g}: overshoot {:.1f} % (linear {:.1f} %), settling {} (linear {}), final error {:.3g}; "
               "of the {}\n",
               sim.amplitude, 100.0 * m.overshoot, 100.0 * l.overshoot, time_or_never(m.settling_time), time_or_never(l.settling_time),
               m.final_error, judged_variable(sim));
  } else {
    fmt::print("  load step of {:.4g}: peak deviation {:.4g} (linear {:.4g}), recovery {} (linear {}), final deviation "
               "{:.3g} (linear {:.3g}); of the {}\n",
               sim.amplitude, m.peak_deviation, l.peak_deviation, time_or_never(m.recovery_time), time_or_never(l.recovery_time),
               0.0 - m.final_error, 0.0 - l.final_error, judged_variable(sim));
  }
  for (const std::string& n : sim.notes) fmt::print("  note: {}\n", n);
}

/// The design run on the plant description with its nonlinearities: a unit setpoint step, then a
/// load step as large as the step's peak torque on the linear part (comparable torque levels
/// whatever the units). A plant that cannot be run this way only gets a note.
std::vector<vcnc::DriveSimulation> verify_on_plant(const TunePlant& plant, const tuning::Controller& controller) {
  std::vector<vcnc::DriveSimulation> runs;
  if (!plant.description) return runs;
  try {
    fmt::print("verified by simulation on the plant with its nonlinearities:\n");
    runs.push_back(vcnc::simulate_drive(*plant.description, controller));
    print_verification(runs.back());
    if (!vcnc::has_load_torque_input(*plant.description)) {
      fmt::print("  load step: not simulated (a transfer-function plant has no load-torque input)\n");
      return runs;
    }
    vcnc::DriveSimulationSettings load;
    load.test = vcnc::DriveTest::kLoadStep;
    load.amplitude = runs.back().linear_metrics.peak_torque;
    runs.push_back(vcnc::simulate_drive(*plant.description, controller, load));
    print_verification(runs.back());
  } catch (const core::InputError& e) {
    fmt::print("  not simulated: {}\n", e.what());
  }
  return runs;
}

int run(const TuneArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  TunePlant plant = load_tune_plant(a.plant);
  const auto report_file = open_report(a.report, global);
  const tuning::TuneOptions options = options_from(a, plant);
  auto out = a.out.empty() ? nullptr : open_output(a.out, global);
  tuning::TuneResult result = tuning::tune(plant.model, options);
  for (const std::string& n : plant.notes) result.controller.notes.push_back(n);
  print_summary(result, a.plant);
  std::vector<vcnc::DriveSimulation> verification = verify_on_plant(plant, result.controller);
  if (out) {
    out->stream() << io::controller_to_json(result.controller, a.plant).dump(2) << "\n";
    out->commit();
    progress(global, "wrote {} ({:.0f} ms)", a.out, elapsed_ms(start));
  }
  if (report_file) {
    report::TuningReportOptions report_options;
    report_options.source = a.plant;
    report_options.w2 = options.w2;
    report_options.simulations = std::move(verification);
    write_report(report::tuning_report(result, report_options), *report_file, global);
  }
  return kSuccess;
}

}  // namespace

void register_tune(CLI::App& app, Action& selected) {
  auto a = std::make_shared<TuneArgs>();
  CLI::App* cmd = app.add_subcommand(
      "tune",
      "Tune a cascade PI/PID velocity loop (and P position loop) or a full-order LQG or H-infinity controller for a "
      "flexible drive from its plant model");
  cmd->add_option("plant", a->plant,
                  "Plant: a fitted model (servotwin.plant-model/1 from `servotwin fit`), a plant description "
                  "(servotwin.plant/1) or a flexible preset name");
  cmd->add_option("--structure", a->structure,
                  "pi, pid (virtual inertia, C7.5), pi+p (P position loop over the PI), lqg (full-order velocity "
                  "LQG, C7.13), lqg+p (P position loop over the LQG), hinf (H-infinity mixed-sensitivity velocity "
                  "loop, C7.14), lqg-pos (full-order position LQG with its reference prefilter, C7.13), hinf-pos "
                  "(H-infinity position loop with a reference prefilter, C7.14), hinf-load (H-infinity velocity "
                  "loop measuring the load velocity: a load encoder, C7.17) or lqg-load (LQG velocity loop with "
                  "integral action on the load, measuring motor and load velocity, C7.17)")
      ->check(CLI::IsMember({"pi", "pid", "pi+p", "lqg", "lqg+p", "hinf", "lqg-pos", "hinf-pos", "hinf-load",
                             "lqg-load"}))
      ->capture_default_str();
  cmd->add_option("--zeta-star", a->zeta_star, "Damping of the assigned closed-loop pole pair")->capture_default_str();
  cmd->add_option("--omega-star", a->omega_star,
                  "Natural frequency of the assigned pair relative to the antiresonance (omega*/omega_z), or auto: "
                  "the largest load bandwidth within --ms/--mt")
      ->capture_default_str();
  cmd->add_option("--kbw", a->kbw,
                  "LQG: bandwidth knob of the normalized weights (larger = slower), or auto: the largest load bandwidth within "
                  "--ms/--mt (and robust tracking with W2)")
      ->capture_default_str();
  cmd->add_option("--kff", a->kff,
                  "LQG: velocity-reference feedforward to the torque (normalized), or auto: the largest keeping the "
                  "tracking peak within --mt")
      ->capture_default_str();
  cmd->add_flag("--raw-motor-velocity", a->raw_motor_velocity,
                "LQG: feed back the measured motor velocity instead of its estimate (C7.13 variant)");
  cmd->add_option("--measurement-noise", a->measurement_noise,
                  "LQG: Kalman-filter measurement-noise intensity V; larger = a slower estimator, for loops with "
                  "delay or a noisy encoder (default: C7.13's 0.1, raised by decades when no kbw meets the spec)");
  cmd->add_option("--omega-0s", a->omega_0s,
                  "H-infinity: w0S/omega_z, the dominant closed-loop pole pair of the weights V and W2, or auto: the "
                  "largest load bandwidth within --ms/--mt (C7.14's search)")
      ->capture_default_str();
  cmd->add_option("--omega-0t", a->omega_0t,
                  "H-infinity: w0T/omega_z, the bandwidth cap of W2, or auto: r, raised to 2r, 4r, 8r while the spec "
                  "fails")
      ->capture_default_str();
  cmd->add_option("--xi-v", a->xi_v, "H-infinity: damping of the relocated resonant pair, in [0.707, 1]")
      ->capture_default_str();
  cmd->add_option("--modes", a->modes,
                  "H-infinity on a plant with higher modes (C7.16): active (design on the full model, damp every "
                  "mode), passive (design on it, cancel the higher modes: a notch) or first (design on mode 1, "
                  "check on the full model); LQG: first designs on mode 1, the others on the extended model")
      ->check(CLI::IsMember({"active", "passive", "first"}))
      ->capture_default_str();
  cmd->add_option("--drive-filter", a->drive_filters,
                  "A filter the drive runs at the controller's output (repeatable): notch:auto (on the mode the PI "
                  "cannot damp, sized by the bandwidth search), notch:F_HZ:WIDTH_HZ:DEPTH_DB, lowpass:F_HZ[:ZETA] or "
                  "biquad:FZ_HZ:ZETA_Z:FP_HZ:ZETA_P; designed with, written as continuous and discrete biquad "
                  "coefficients at --ts (required). pi, pid, pi+p; H-infinity takes one first-order lowpass (its roll-off)");
  cmd->add_option("--rolloff-hz", a->rolloff_hz,
                  "The lowpass case of --drive-filter: a first-order low-pass at the controller's output with this "
                  "corner [Hz], designed with. H-infinity: a strictly proper controller that rolls off above it (C7.14's "
                  "is biproper: its gain stays flat at high frequency, amplifying sensor noise)");
  cmd->add_option("--controller-order", a->controller_order,
                  "H-infinity: reduce the controller to this many states by balanced truncation of its stable part "
                  "(the integrator and unstable poles are kept; default: its minimal realization)");
  cmd->add_option("--target-r", a->target_r, "PID: virtual resonance ratio r-bar the derivative gain creates, or auto (the largest bandwidth "
                  "between 2 and 0.9 r: for lags or delays that leave no phase for the derivative)")
      ->capture_default_str();
  cmd->add_option("--tau", a->tau, "PID: derivative filter time constant [s] (default: 1/max(r, 5 omega*) in omega_z units)");
  cmd->add_flag("--allow-negative-kd", a->allow_negative_kd, "PID: accept a negative Kd (r < r-bar: acceleration feedback)");
  add_spec_options(*cmd, a->spec);
  cmd->add_option("--setpoint-weight", a->setpoint_weight, "Proportional setpoint weight wp in [0, 1] (2-DoF)")
      ->capture_default_str();
  add_output_file_option(*cmd, a->out, "Write the controller (servotwin.controller/1 JSON; - for stdout)");
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin tune plant_model.json -o controller.json\n"
               "  servotwin tune plant_model.json --structure pid --target-r 2 --ts 0.000125 -o pid.json\n"
               "  servotwin tune table-5.1 --structure pi+p --omega-star 0.4 --zeta-star 1 --report tune.html\n"
               "  servotwin tune plant_model.json --w2-from-frf frf.csv\n"
               "  servotwin tune table-5.1 --structure lqg --ts 0.000125 -o lqg.json --report lqg.html\n"
               "  servotwin tune table-5.1 --structure hinf --ts 0.000125 -o hinf.json\n"
               "  servotwin tune table-5.1 --structure lqg-pos --ts 0.000125 -o lqg-pos.json\n"
               "  servotwin tune table-5.1 --structure hinf-load -o hinf-load.json\n"
               "  servotwin tune table-5.1 --structure lqg-load --ts 0.000125 -o lqg-load.json\n"
               "  servotwin tune plant_model.json --delay 0.0005 --w2-num 2.6,0 --w2-den 1,15 --ms 1.6\n"
               "  servotwin tune testbed-2 --ms 2.5 --mt 2.5 --drive-filter notch:auto -o pi_notch.json\n"
               "  servotwin tune plant_model.json --ts 0.000125 --drive-filter notch:180:60:20 --drive-filter lowpass:800\n");
  add_tune_compare(*cmd, selected);
  cmd->callback([a, cmd, &selected] {
    if (cmd->got_subcommand("compare")) return;  // its own callback chose the action
    if (a->plant.empty()) throw CLI::RequiredError("plant");
    selected = [a](const GlobalOptions& g) { return run(*a, g); };
  });
}

}  // namespace servotwin::cli
