// `servotwin fit`: fit a plant model (two-mass, n modes, or automatic order) to a measured
// frequency response and write plant_model.json.
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "command.hpp"
#include "report_output.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/fit/fit.hpp"
#include "servotwin/fit/friction_fit.hpp"
#include "servotwin/fit/nonlinear.hpp"
#include "servotwin/io/frf_csv.hpp"
#include "servotwin/io/plant_model_json.hpp"
#include "servotwin/report/fit_report.hpp"

namespace servotwin::cli {

namespace {


struct FitArgs {
  std::string frf;
  std::string model = "two-mass";
  std::string output_kind = "auto";
  std::string rigid = "pole";
  std::string sensor = "motor";
  bool lag = false;
  bool delay = false;
  std::size_t max_modes = 4;
  int max_iterations = 200;
  std::string out;
  std::string report;
  std::vector<std::string> amplitude_series;
  bool friction = false;
};

/// "12.3 ± 0.4" (the ± part omitted when not identifiable).
std::string pm(double value, double std) {
  if (!std::isfinite(std)) return fmt::format("{:.5g} (std n/a)", value);
  return fmt::format("{:.5g} ± {:.2g}", value, std);
}

void print_summary(const std::string& source, const fit::FitReport& r) {
  const fit::FitResult& f = r.result;
  const fit::PlantModel& m = f.model;
  fmt::print("{}: {} points, {} output ({})\n", source, f.points, fit::to_string(m.output), r.output.note);
  if (!r.left_out.empty()) {
    fmt::print("left out {} {} (marked invalid by the measurement, or outliers of the first fit):\n", r.left_out.size(),
               plural(r.left_out.size(), "point", "points"));
    for (const std::string& why : r.left_out) fmt::print("  {}\n", why);
  }
  fmt::print("model: {} {}{}, rigid {}{}{}; {}\n", m.modes.size(), m.sensor == fit::SensorSide::kLoad ? "load-side " : "",
             plural(m.modes.size(), "mode", "modes"), fit::to_string(m.rigid),
             m.lag_pole_rad_s ? ", lag pole" : "", m.delay_s ? ", delay" : "", r.selection.criterion);
  if (r.selection.method == "auto")
    for (const auto& c : r.selection.candidates)
      fmt::print("  n = {}: {} parameters, cost {:.4g}, score {:.4g}{}\n", c.modes, c.parameters, c.cost, c.score,
                 c.converged ? (c.modes == r.selection.chosen ? "  <- chosen" : "") : "  (did not converge)");
  fmt::print("fit: {} iterations from the {} start, {}; rms log error {:.3g} ({} weighting)\n", f.iterations,
             f.initialization, f.message, f.rms_log_error, f.weighting);
  if (!f.uncertainty_note.empty()) fmt::print("  ({})\n", f.uncertainty_note);
  fmt::print("  gain K          = {}\n", pm(f.gain.value, f.gain.std));
  if (m.rigid == fit::RigidKind::kRealPole)
    fmt::print("  rigid pole      = {} Hz\n", pm(f.rigid_pole_rad_s.value / kTwoPi, f.rigid_pole_rad_s.std / kTwoPi));
  if (m.lag_pole_rad_s)
    fmt::print("  lag pole        = {} Hz\n", pm(f.lag_pole_rad_s.value / kTwoPi, f.lag_pole_rad_s.std / kTwoPi));
  if (m.delay_s) fmt::print("  delay           = {} s\n", pm(f.delay_s.value, f.delay_s.std));
  for (std::size_t i = 0; i < f.mode_estimates.size(); ++i) {
    const auto& u = f.mode_estimates[i];
    if (m.sensor == fit::SensorSide::kMotor)
      fmt::print("  mode {}: antiresonance {} Hz, zeta {}\n", i + 1,
                 pm(u.antiresonance_omega.value / kTwoPi, u.antiresonance_omega.std / kTwoPi),
                 pm(u.antiresonance_zeta.value, u.antiresonance_zeta.std));
    fmt::print("  {:<8}resonance     {} Hz, zeta {}\n",
               m.sensor == fit::SensorSide::kMotor ? "" : fmt::format("mode {}:", i + 1),
               pm(u.resonance_omega.value / kTwoPi, u.resonance_omega.std / kTwoPi), pm(u.resonance_zeta.value, u.resonance_zeta.std));
  }
  if (const auto& p = f.physical.parameters) {
    fmt::print("physical two-mass parameters (input/output units of the data):\n");
    fmt::print("  motor inertia Im = {}\n  load inertia  Il = {}\n  stiffness     k  = {}\n  damping       b  = {}\n"
               "  ratio r = wn/wz  = {}   (zeta_p / (r zeta_z) = {:.3g}; 1 for a pure shaft damper)\n",
               pm(p->motor_inertia.value, p->motor_inertia.std), pm(p->load_inertia.value, p->load_inertia.std),
               pm(p->stiffness.value, p->stiffness.std), pm(p->damping.value, p->damping.std),
               pm(p->resonance_ratio.value, p->resonance_ratio.std), p->damping_consistency);
  } else {
    fmt::print("physical parameters: none ({})\n", f.physical.note);
  }
}

void print_nonlinear(const fit::NonlinearMechanics& n) {
  fmt::print("nonlinear mechanics (describing functions, C5.10):\n");
  if (n.coulomb.estimated)
    fmt::print("  Coulomb friction M = {} (input units){}\n", pm(n.coulomb.level, n.coulomb.level_std),
               n.coulomb.significant ? "" : "  not significant");
  fmt::print("    {}\n", n.coulomb.note);
  for (const auto& r : n.backlash.runs)
    fmt::print("  amplitude {:.4g}: antiresonance {} Hz, shaft stiffness seen {:.5g}, twist {:.3g}\n", r.amplitude,
               pm(r.antiresonance_hz, r.antiresonance_hz_std), r.effective_stiffness, r.twist_amplitude);
  if (n.backlash.estimated && n.backlash.significant)
    fmt::print("  backlash D = {:.4g} (position unit of the output: rad for rad/s data), shaft stiffness {:.5g}\n", n.backlash.width,
               n.backlash.stiffness);
  fmt::print("    {}\n", n.backlash.note);
}

/// "a, b, c" of values with their std.
std::string estimates(const std::vector<fit::Estimate>& v) {
  std::string text;
  for (const fit::Estimate& e : v) text += (text.empty() ? "" : ", ") + pm(e.value, e.std);
  return text;
}

void print_friction(const fit::CoulombFit& c) {
  if (!c.fitted) {
    fmt::print("{}\n", c.note);
    return;
  }
  const bool motor = c.model.sensor == fit::SensorSide::kMotor;
  fmt::print("with Coulomb friction ({}): rms log error {:.3g} (linear fit {:.3g}); {}\n", c.note, c.rms_log_error,
             c.linear_rms_log_error, c.message);
  fmt::print("  Coulomb friction motor Mm = {}, load Ml = {} (input units)\n", pm(c.motor_coulomb.value, c.motor_coulomb.std),
             pm(c.load_coulomb.value, c.load_coulomb.std));
  fmt::print("  linear part (written as the model):\n");
  if (c.model.rigid == fit::RigidKind::kRealPole)
    fmt::print("  rigid pole      = {} Hz (viscous damping {:.4g})\n",
               pm(c.rigid_pole_rad_s.value / kTwoPi, c.rigid_pole_rad_s.std / kTwoPi), c.viscous_damping.value);
  else
    fmt::print("  rigid           = integrator (no viscous damping found)\n");
  for (std::size_t i = 0; i < c.model.modes.size() && i < c.modes.size(); ++i) {
    const fit::Mode& m = c.model.modes[i];
    const fit::ModeUncertainty& u = c.modes[i];
    if (motor)
      fmt::print("  mode {}: antiresonance {} Hz, zeta {}\n", i + 1, pm(m.antiresonance.omega_rad_s / kTwoPi, u.antiresonance_omega.std / kTwoPi),
                 pm(m.antiresonance.zeta, u.antiresonance_zeta.std));
    fmt::print("  {:<8}resonance     {} Hz, zeta {}\n", motor ? "" : fmt::format("mode {}:", i + 1),
               pm(m.resonance.omega_rad_s / kTwoPi, u.resonance_omega.std / kTwoPi), pm(m.resonance.zeta, u.resonance_zeta.std));
  }
  if (!motor)
    fmt::print("  total inertia J = {}, motor's share Jm/J = {} (seen through the friction only)\n",
               pm(c.total_inertia.value, c.total_inertia.std), pm(c.motor_share.value, c.motor_share.std));
  if (!motor && c.stiffnesses.size() == 1) return;
  if (c.stiffnesses.size() != 1) {
    fmt::print("  inertias       = {} (motor first)\n  stiffnesses    = {}\n  shaft dampings = {}\n", estimates(c.inertias),
               estimates(c.stiffnesses), estimates(c.shaft_dampings));
    return;
  }
  fmt::print("  motor inertia Im = {}\n  load inertia  Il = {}\n  stiffness     k  = {}\n  shaft damping b  = {}\n",
             pm(c.motor_inertia.value, c.motor_inertia.std), pm(c.load_inertia.value, c.load_inertia.std),
             pm(c.stiffness.value, c.stiffness.std), pm(c.shaft_damping.value, c.shaft_damping.std));
}

fit::FitOptions options_from(const FitArgs& a) {
  fit::FitOptions o;
  if (a.output_kind == "velocity")
    o.output = fit::OutputChoice::kVelocity;
  else if (a.output_kind == "position")
    o.output = fit::OutputChoice::kPosition;
  else
    o.output = fit::OutputChoice::kDetect;
  o.rigid = a.rigid == "integrator" ? fit::RigidKind::kIntegrator : fit::RigidKind::kRealPole;
  o.sensor = a.sensor == "load" ? fit::SensorSide::kLoad : fit::SensorSide::kMotor;
  o.lag = a.lag;
  o.delay = a.delay;
  o.max_modes = a.max_modes;
  o.max_iterations = a.max_iterations;
  return o;
}

int run(const FitArgs& a, const GlobalOptions& global) {
  const auto start = std::chrono::steady_clock::now();
  const fit::ModelRequest request = fit::parse_model_request(a.model);
  if (a.sensor == "load" && !a.amplitude_series.empty())
    throw core::InputError(core::at_field("--amplitude-series"),
                           "the amplitude-series analysis of friction and backlash reads the motor side's antiresonance, "
                           "which a load-side response (--sensor load) does not have: use --friction, or measure with "
                           "the motor encoder");
  const core::FrequencyResponse response = io::read_frf_file(a.frf);
  const auto report_file = open_report(a.report, global);
  fit::FitReport fitted;
  try {
    fitted = fit::fit_plant(response, request, options_from(a));
  } catch (const core::InputError& e) {
    // Point-level problems name "points[i]..."; say which file they are in.
    if (e.where().field.rfind("points", 0) == 0) throw core::InputError({a.frf, 0, 0, e.where().field}, e.reason());
    if (a.sensor == "motor" && e.reason().find("load-side response") != std::string::npos)
      throw core::InputError(e.where(), e.reason() + " (--sensor load)");
    throw;
  }
  print_summary(a.frf, fitted);
  std::optional<fit::NonlinearMechanics> nonlinear;
  if (!a.amplitude_series.empty()) {
    std::vector<core::FrequencyResponse> experiments{response};
    for (const auto& path : a.amplitude_series) experiments.push_back(io::read_frf_file(path));
    nonlinear = fit::analyze_nonlinear_mechanics(fitted, experiments, options_from(a));
    print_nonlinear(*nonlinear);
  }
  std::optional<fit::CoulombFit> friction;
  if (a.friction) {
    friction = fit::fit_coulomb_friction(response, fitted, options_from(a));
    print_friction(*friction);
  }
  const fit::FitReport written = friction ? fit::with_friction_model(fitted, *friction) : fitted;
  if (!a.out.empty()) {
    auto out = open_output(a.out, global);
    out->stream() << io::plant_model_to_json(written, nonlinear ? &*nonlinear : nullptr,
                                             friction && friction->fitted ? &*friction : nullptr)
                         .dump(2)
                  << "\n";
    out->commit();
    progress(global, "wrote {} ({:.0f} ms)", a.out, elapsed_ms(start));
  }
  if (report_file)
    write_report(report::fit_report(response, written, a.frf, nonlinear ? &*nonlinear : nullptr, friction ? &*friction : nullptr),
                 *report_file, global);
  return kSuccess;
}

}  // namespace

void register_fit(CLI::App& app, Action& selected) {
  auto a = std::make_shared<FitArgs>();
  CLI::App* cmd = app.add_subcommand("fit", "Fit a plant model (two-mass, n modes or automatic order) to a measured frequency response");
  cmd->add_option("frf", a->frf, "Frequency-response CSV (servotwin.frf/1: freq_hz, re, im or mag_db, phase_deg)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--model", a->model,
                  "two-mass (rigid mode + one mode, C5.7), modes:N (N flexible modes) or auto (order chosen by BIC, or by "
                  "the noise level when the file has std)")
      ->capture_default_str();
  cmd->add_option("--output-kind", a->output_kind, "Measured output: velocity, position, or auto (from the low-frequency slope)")
      ->check(CLI::IsMember({"auto", "velocity", "position"}))
      ->capture_default_str();
  cmd->add_option("--rigid", a->rigid, "Rigid-body mode: pole (K/(s+a), viscous friction) or integrator (K/s)")
      ->check(CLI::IsMember({"pole", "integrator"}))
      ->capture_default_str();
  cmd->add_option("--sensor", a->sensor,
                  "Where the response was measured: motor (collocated: each mode an antiresonance and its resonance) "
                  "or load (a load encoder: resonances alone, each with the shaft's damping zero)")
      ->check(CLI::IsMember({"motor", "load"}))
      ->capture_default_str();
  cmd->add_flag("--lag", a->lag, "Also fit a lag pole 1/(s+tau2) (sampling, communication and actuator lag)");
  cmd->add_flag("--delay", a->delay, "Also fit a pure delay exp(-sT)");
  cmd->add_option("--max-modes", a->max_modes, "Largest number of modes tried by --model auto")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  cmd->add_option("--max-iterations", a->max_iterations, "Levenberg-Marquardt iteration limit per start")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  add_output_file_option(*cmd, a->out, "Write the model (servotwin.plant-model/1 JSON; - for stdout)")
      ->check([](const std::string& value) {
        return value == "velocity" || value == "position" || value == "auto"
                   ? std::string("--output names the file written now; the measured output is --output-kind " + value)
                   : std::string();
      });
  cmd->add_option("--amplitude-series", a->amplitude_series,
                  "Responses of the same plant measured at other excitation amplitudes (the main file should be the "
                  "largest): Coulomb friction and backlash from their describing functions")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--friction", a->friction,
                "Also fit Coulomb friction on motor and load (a mass chain of one mass more than the fitted modes, "
                "either --sensor; describing functions at each point's excitation amplitude, swept-sine "
                "responses): friction is told apart from "
                "the linear damping, and -o writes the linear part");
  add_report_option(*cmd, a->report);
  set_examples(*cmd,
               "  servotwin fit frf.csv -o plant_model.json --report fit.html\n"
               "  servotwin fit frf.csv --model modes:2 --lag -o plant_model.json\n"
               "  servotwin fit frf.csv --lag --friction -o plant_model.json\n"
               "  servotwin fit load_frf.csv --sensor load --lag -o load_model.json\n"
               "  servotwin fit frf.csv --model auto --output-kind velocity --rigid integrator\n"
               "  servotwin fit frf_2Nm.csv --delay --amplitude-series frf_0.25Nm.csv -o plant_model.json\n");
  cmd->callback([a, &selected] { selected = [a](const GlobalOptions& g) { return run(*a, g); }; });
}

}  // namespace servotwin::cli
