#include "servotwin/report/tuning_report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "bode.hpp"
#include "number_format.hpp"
#include "chart_helpers.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/report/drive_report.hpp"
#include "servotwin/tuning/position_loop.hpp"
#include "servotwin/tuning/uncertainty.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::report {

namespace {

using Complex = std::complex<double>;
using detail::db_of;
using detail::flat;
using detail::frequency_chart;
using detail::magnitude_db;
using detail::scaled;
using detail::time_grid;
using detail::TimeGrid;
using detail::unwrapped_phase_deg;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kMinPoints = 16;
/// The frequency charts span this factor below the lower of ωz and ω* and above the highest plant
/// frequency (resonance or higher mode): the low-frequency asymptotes and the roll-off.
constexpr double kFactorBelow = 100.0;
constexpr double kFactorAbove = 20.0;
/// Closed-loop poles with less damping than this put their damped frequency into the grid (as
/// the analysis does), so that their narrow peaks are drawn at their height.
constexpr double kLightDamping = 0.5;
/// The analysis' simulation rule (loop_analysis.hpp), applied to the position loop's poles.
constexpr double kHorizonTimeConstants = 15.0;
constexpr double kStepPerFastestPole = 0.02;

std::string num(double v, int digits = 5) { return detail::format_number(v, digits); }

std::string yes_no(bool v) { return v ? "yes" : "no"; }

/// Everything the sections share: the plant's scales and the frequency grid.
struct Context {
  const tuning::TuneResult& result;
  const TuningReportOptions& options;
  const tuning::NormalizedPlant& plant;
  const tuning::Controller& controller;
  std::vector<double> omega;  ///< normalized grid
  std::vector<double> hz;     ///< the same in Hz

  [[nodiscard]] double to_hz(double omega_normalized) const { return omega_normalized * plant.omega_z / kTwoPi; }
  [[nodiscard]] double to_seconds(double t_normalized) const { return t_normalized / plant.omega_z; }
  /// Velocity per torque: normalized → model units (torque is scaled by Im ωz, velocity is not).
  [[nodiscard]] double velocity_per_torque() const { return 1.0 / (plant.motor_inertia * plant.omega_z); }
  /// Position per torque: one more 1/ωz from the integration in normalized time.
  [[nodiscard]] double position_per_torque() const { return velocity_per_torque() / plant.omega_z; }
  /// Torque per velocity (controller gain): normalized → model units.
  [[nodiscard]] double torque_per_velocity() const { return plant.motor_inertia * plant.omega_z; }
  /// A full-order position controller: the loop functions and indices are positions.
  [[nodiscard]] bool position() const { return tuning::is_position_controller(controller.structure); }
  /// The judged variable of the tracking and disturbance functions: "ω" or "φ".
  [[nodiscard]] const char* variable() const { return position() ? "φ" : "ω"; }
  /// Per torque of the judged outputs (velocity or position) in model units.
  [[nodiscard]] double output_per_torque() const { return position() ? position_per_torque() : velocity_per_torque(); }
  /// Torque per unit reference (velocity, or position: one more ωz) in model units.
  [[nodiscard]] double torque_per_reference() const {
    return position() ? torque_per_velocity() * plant.omega_z : torque_per_velocity();
  }
};

/// The log grid with the `exact` frequencies inside its span added, sorted, and points closer than
/// 1e-6 relative merged (two x values printing alike would collapse in the chart).
std::vector<double> with_exact_points(std::vector<double> grid, const std::vector<double>& exact) {
  const double lo = grid.front(), hi = grid.back();
  for (double w : exact)
    if (std::isfinite(w) && w > lo && w < hi) grid.push_back(w);
  std::sort(grid.begin(), grid.end());
  std::vector<double> out;
  for (double w : grid)
    if (out.empty() || w > out.back() * (1.0 + 1e-6)) out.push_back(w);
  return out;
}

std::vector<double> frequency_grid(const tuning::TuneResult& r, std::size_t points) {
  const tuning::NormalizedPlant& p = r.plant;
  double top = p.r;
  std::vector<double> exact{1.0, p.r, r.controller.design.omega_star};
  for (const fit::Mode& m : p.higher_modes) {
    top = std::max(top, m.resonance.omega_rad_s);
    exact.push_back(m.antiresonance.omega_rad_s);
    exact.push_back(m.resonance.omega_rad_s);
  }
  const tuning::LoopIndices& i = r.controller.predicted;
  for (const Complex& pole : i.closed_loop_poles)
    if (-pole.real() < kLightDamping * std::abs(pole)) exact.push_back(std::abs(pole.imag()));
  exact.insert(exact.end(), {i.peak_s_omega, i.gain_crossover, i.phase_crossover});
  // The crossovers (where the HF dynamics act) stay inside the chart.
  for (double w : {i.gain_crossover, i.phase_crossover})
    if (std::isfinite(w)) top = std::max(top, 3.0 * w / kFactorAbove);
  // A full-order design has no ω*: its motor bandwidth marks the low end instead.
  double low = 1.0;
  for (double w : {r.controller.design.omega_star, i.bandwidth_motor})
    if (std::isfinite(w) && w > 0.0) low = std::min(low, w);
  const double bottom = low / kFactorBelow;
  return with_exact_points(core::log_space(bottom, kFactorAbove * top, points), exact);
}

/// A vertical marker at x from y0 to y1: two points 1e-6 apart in x (a line chart aligns its
/// series on x, so two points at one x would merge).
Series vertical(std::string label, double x, double y0, double y1) {
  return {std::move(label), {x * (1.0 - 1e-6), x * (1.0 + 1e-6)}, {y0, y1}};
}

double db(double v) { return 20.0 * std::log10(v); }

// ---------------------------------------------------------------- 1. plant

Table plant_table(const Context& c) {
  const tuning::NormalizedPlant& p = c.plant;
  Table t;
  t.title = "Normalized plant (catalog §0: time scaled by ωz, torque by Im ωz)";
  t.header = {"quantity", "value", "unit / meaning"};
  t.rows.push_back({"antiresonance ωz", num(c.to_hz(1.0)), "Hz (the time scale)"});
  t.rows.push_back({"resonance r ωz", num(c.to_hz(p.r)), "Hz"});
  t.rows.push_back({"resonance ratio r", num(p.r), "ωn/ωz"});
  t.rows.push_back({"antiresonance damping ζz", num(p.zeta_z), ""});
  t.rows.push_back(
      {"resonance damping ζp", num(p.zeta_p), fmt::format("frictionless two-mass: r ζz = {}", num(p.r * p.zeta_z))});
  t.rows.push_back({"rigid pole a", num(p.a), fmt::format("× ωz = {} Hz (0: integrator)", num(c.to_hz(p.a)))});
  t.rows.push_back({"motor inertia Im", num(p.motor_inertia), "model units (from the high-frequency asymptote)"});
  t.rows.push_back({"measured output", fit::to_string(p.output), ""});
  t.rows.push_back({"frictionless relations hold (5 %)", yes_no(p.frictionless_consistent()),
                    "ζp ≈ r ζz and a ≈ 0 (only then do the closed forms 7.36/7.63 apply)"});
  return t;
}

Table higher_modes_table(const Context& c) {
  Table t;
  t.title = "Higher modes (evaluated, not designed for)";
  t.header = {"mode", "antiresonance [Hz]", "ζ", "resonance [Hz]", "ζ"};
  for (std::size_t i = 0; i < c.plant.higher_modes.size(); ++i) {
    const fit::Mode& m = c.plant.higher_modes[i];
    t.rows.push_back({std::to_string(i + 2), num(c.to_hz(m.antiresonance.omega_rad_s)), num(m.antiresonance.zeta),
                      num(c.to_hz(m.resonance.omega_rad_s)), num(m.resonance.zeta)});
  }
  return t;
}

Table hf_table(const Context& c) {
  const tuning::HfDynamics& hf = c.plant.hf;  // normalized time
  Table t;
  t.title = "Known high-frequency dynamics (designed without, evaluated with)";
  t.header = {"element", "value", "unit"};
  if (hf.current_lag_s) t.rows.push_back({"current-loop lag τc", num(c.to_seconds(*hf.current_lag_s) * 1e3), "ms"});
  if (hf.feedback_filter_s)
    t.rows.push_back({"velocity filter τf", num(c.to_seconds(*hf.feedback_filter_s) * 1e3), "ms"});
  if (hf.delay_s) t.rows.push_back({"delay T", num(c.to_seconds(*hf.delay_s) * 1e3), "ms"});
  if (hf.lag_pole_rad_s) t.rows.push_back({"lag pole p/(s + p)", num(c.to_hz(*hf.lag_pole_rad_s)), "Hz"});
  return t;
}

std::optional<Table> two_mass_table(const Context& c) {
  const std::optional<tuning::FrictionTwoMass> f = tuning::two_mass_realization(c.plant);
  if (!f) return std::nullopt;
  const tuning::PhysicalTwoMass q = tuning::to_physical(*f, c.plant);
  Table t;
  t.title = f->passive() ? "Two-mass realization with viscous friction (model units)"
                         : "Two-mass realization with viscous friction (model units; not passive: the load side is an "
                           "estimate)";
  t.header = {"parameter", "value"};
  t.rows.push_back({"motor inertia Im", num(q.motor_inertia)});
  t.rows.push_back({"load inertia Il", num(q.load_inertia)});
  t.rows.push_back({"shaft stiffness k", num(q.stiffness)});
  t.rows.push_back({"shaft damping b", num(q.damping)});
  t.rows.push_back({"motor viscous friction bm", num(q.motor_viscous)});
  t.rows.push_back({"load viscous friction bl", num(q.load_viscous)});
  return t;
}

/// Bode charts of the plant: the design model (first mode), the model with the higher modes and
/// the model with the known HF dynamics (measured_response, a position output turned back into
/// velocity by jω), all velocity per torque in model units.
std::vector<Chart> plant_charts(const Context& c) {
  const tuning::NormalizedPlant& p = c.plant;
  const core::TransferFunction design = p.motor(false);
  const core::TransferFunction full = p.motor(true);
  const double scale = c.velocity_per_torque();
  std::vector<std::pair<std::string, std::vector<Complex>>> curves;
  curves.emplace_back("design model (first mode)", design.frequency_response(c.omega));
  if (!p.higher_modes.empty()) curves.emplace_back("with the higher modes", full.frequency_response(c.omega));
  if (!p.hf.empty()) {
    std::vector<Complex> g(c.omega.size());
    for (std::size_t k = 0; k < g.size(); ++k) {
      g[k] = p.measured_response(c.omega[k]);
      if (p.output == fit::OutputKind::kPosition) g[k] *= Complex(0.0, c.omega[k]);
    }
    curves.emplace_back("with the known HF dynamics", std::move(g));
  }
  Chart mag = frequency_chart("Plant magnitude |ωm/Tm|", "magnitude [dB, model units]");
  Chart phase = frequency_chart("Plant phase", "phase [deg]");
  for (const auto& [label, g] : curves) {
    mag.series.push_back({label, c.hz, db_of(g, scale)});
    phase.series.push_back({label, c.hz, unwrapped_phase_deg(g)});
  }
  return {std::move(mag), std::move(phase)};
}

Section plant_section(const Context& c) {
  const tuning::NormalizedPlant& p = c.plant;
  Section s;
  s.title = "Plant";
  s.text = fmt::format(
      "Resonance ratio r = {}: {} (catalog C7.4; ω* = ωz is reachable with ζ* = {} for r <= {}).\n\n"
      "The design works on the first mode's model Pm(s) = (1/(s + a))(s^2 + 2 ζz s + 1)/(s^2 + 2 ζp r s + r^2) in "
      "normalized units; {}{}the charts show velocity per torque in the model's units.",
      num(p.r, 4), c.result.advice.verdict, num(c.controller.design.zeta_star, 3),
      num(c.result.advice.r_full_bandwidth, 4), p.higher_modes.empty() ? "" : "the higher modes and ",
      p.hf.empty() ? "" : "the known HF dynamics are included in every evaluation, not in the design; ");
  s.tables.push_back(plant_table(c));
  if (!p.higher_modes.empty()) s.tables.push_back(higher_modes_table(c));
  if (!p.hf.empty()) s.tables.push_back(hf_table(c));
  if (auto t = two_mass_table(c)) s.tables.push_back(std::move(*t));
  s.charts = plant_charts(c);
  return s;
}
// ---------------------------------------------------------------- 2. design

Table design_table(const Context& c) {
  const tuning::DesignParameters& d = c.controller.design;
  const tuning::AdmissibleRange& range = c.result.range;
  Table t;
  t.title = "Design parameters";
  t.header = {"parameter", "normalized", "physical"};
  t.rows.push_back({"structure", tuning::to_string(c.controller.structure), ""});
  t.rows.push_back({"assigned pair ω*", num(d.omega_star), num(c.to_hz(d.omega_star)) + " Hz"});
  t.rows.push_back({"assigned pair damping ζ*", num(d.zeta_star), ""});
  t.rows.push_back({"ω* chosen by", d.omega_star_source, ""});
  t.rows.push_back({"admissible ω* range", fmt::format("[{}, {}]", num(range.omega_min), num(range.omega_max)),
                    fmt::format("[{}, {}] Hz", num(c.to_hz(range.omega_min)), num(c.to_hz(range.omega_max)))});
  t.rows.push_back(
      {"range ends (lower, upper)", tuning::to_string(range.lower) + ", " + tuning::to_string(range.upper), ""});
  if (d.r_target) t.rows.push_back({"virtual resonance ratio r̄ (PID)", num(*d.r_target), ""});
  if (d.ms) t.rows.push_back({"limit Ms on ‖S‖∞", num(*d.ms), ""});
  if (d.mt) t.rows.push_back({"limit Mt on the tracking peak", num(*d.mt), ""});
  return t;
}

/// A drive filter as one row: what it is, and its discrete biquad (b0 b1 b2 / a1 a2) when known.
std::vector<std::string> drive_filter_row(const tuning::DriveFilter& f) {
  const tuning::DriveFilterSpec& s = f.spec;
  std::string what;
  switch (s.type) {
    case tuning::DriveFilterType::kNotch:
      what = fmt::format("notch {} Hz, width {} Hz, depth {} dB", num(s.frequency_hz, 5), num(s.width_hz, 4),
                         num(s.depth_db, 3));
      break;
    case tuning::DriveFilterType::kLowpass:
      what = s.damping ? fmt::format("lowpass {} Hz, damping {}", num(s.frequency_hz, 5), num(*s.damping, 3))
                       : fmt::format("lowpass {} Hz (first order)", num(s.frequency_hz, 5));
      break;
    case tuning::DriveFilterType::kBiquad:
      what = fmt::format("biquad {} Hz/{} over {} Hz/{}", num(s.frequency_hz, 5), num(*s.damping, 3),
                         num(s.pole_frequency_hz, 5), num(s.pole_damping, 3));
      break;
  }
  if (s.automatic) what += " (notch:auto" + (f.reason.empty() ? std::string() : ": " + f.reason) + ")";
  const std::string biquad =
      f.discrete ? fmt::format("b = {} {} {}; a1 a2 = {} {}", num(f.discrete->b0, 10), num(f.discrete->b1, 10),
                               num(f.discrete->b2, 10), num(f.discrete->a1, 10), num(f.discrete->a2, 10))
                 : std::string();
  return {"drive filter", what, biquad, ""};
}

Table gains_table(const Context& c) {
  const tuning::PidGains& n = c.controller.normalized;
  const tuning::PidGains& p = c.controller.physical;
  Table t;
  t.title = "Gains";
  t.header = {"gain", "normalized", "physical (model units)", "unit"};
  t.rows.push_back({"Kp", num(n.kp, 7), num(p.kp, 7), "torque per velocity"});
  t.rows.push_back({"Ki", num(n.ki, 7), num(p.ki, 7), "torque per velocity × 1/s"});
  if (n.kd != 0.0) {
    t.rows.push_back({"Kd", num(n.kd, 7), num(p.kd, 7), "torque per velocity × s"});
    t.rows.push_back({"derivative filter τ", num(n.tau, 5), num(p.tau * 1e3, 5), "ms"});
    t.rows.push_back({"derivative setpoint weight wd", num(n.wd, 3), num(p.wd, 3), ""});
  }
  t.rows.push_back({"proportional setpoint weight wp", num(n.wp, 3), num(p.wp, 3), ""});
  if (c.controller.kpp_normalized && c.controller.kpp_physical)
    t.rows.push_back(
        {"position gain Kpp", num(*c.controller.kpp_normalized, 7), num(*c.controller.kpp_physical, 7), "1/s"});
  if (c.controller.discrete)
    t.rows.push_back({"discretized (Tustin) at ts", "", num(c.controller.discrete->ts * 1e3, 5), "ms"});
  for (const tuning::DriveFilter& f : c.controller.drive_filters) t.rows.push_back(drive_filter_row(f));
  return t;
}

/// The automatic ω* scan: the bandwidth and the peaks of every candidate, the limits, the choice.
std::vector<Chart> scan_charts(const Context& c, bool load) {
  const auto& scan = c.result.scan;
  const tuning::DesignParameters& d = c.controller.design;
  std::vector<double> x, bandwidth, feasible_bandwidth, peak_s, peak_tracking;
  for (const tuning::TuneResult::Candidate& k : scan) {
    x.push_back(c.to_hz(k.omega_star));
    // An unstable candidate has no bandwidth or peaks: a gap.
    bandwidth.push_back(k.stable ? c.to_hz(k.bandwidth) : kNaN);
    feasible_bandwidth.push_back(k.feasible ? c.to_hz(k.bandwidth) : kNaN);
    peak_s.push_back(k.stable ? k.peak_s : kNaN);
    peak_tracking.push_back(k.stable ? k.peak_tracking : kNaN);
  }
  const std::string side = load ? "load" : "motor";
  const double chosen = c.to_hz(d.omega_star);

  // Linear ω* axes: the candidates span at most a factor 50 (from 0.02 ωmax), and a logarithmic
  // axis over less than two decades snaps back to whole decades when drag-zoomed.
  Chart bw;
  bw.title = "Automatic ω*: " + side + " bandwidth of each candidate";
  bw.x_label = "ω* [Hz]";
  bw.y_label = side + " velocity bandwidth [Hz]";
  bw.series.push_back({"all stable candidates", x, bandwidth});
  bw.series.push_back({"candidates within the limits", x, feasible_bandwidth});
  double top = 0.0;
  for (double v : bandwidth)
    if (std::isfinite(v)) top = std::max(top, v);
  bw.series.push_back(vertical("chosen ω*", chosen, 0.0, top > 0.0 ? top : 1.0));

  Chart peaks;
  peaks.title = "Automatic ω*: peaks of each candidate";
  peaks.x_label = "ω* [Hz]";
  peaks.y_label = "peak (absolute)";
  peaks.series.push_back({"‖S‖∞", x, peak_s});
  peaks.series.push_back({load ? "‖ωl/ω*‖∞" : "‖ωm/ω*‖∞", x, peak_tracking});
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (const auto* v : {&peak_s, &peak_tracking})
    for (double p : *v)
      if (std::isfinite(p)) {
        lo = std::min(lo, p);
        hi = std::max(hi, p);
      }
  if (d.ms) {
    peaks.series.push_back(flat("Ms", x, *d.ms));
    hi = std::max(hi, *d.ms);
  }
  if (d.mt) {
    peaks.series.push_back(flat("Mt", x, *d.mt));
    hi = std::max(hi, *d.mt);
  }
  if (hi > 0.0) peaks.series.push_back(vertical("chosen ω*", chosen, std::isfinite(lo) ? std::min(lo, 1.0) : 1.0, hi));
  return {std::move(bw), std::move(peaks)};
}

Table scan_table(const Context& c) {
  Table t;
  t.title = "Automatic ω* scan";
  t.header = {"ω* [Hz]", "ω*/ωz", "stable", "bandwidth [Hz]", "‖S‖∞", "tracking peak", "within the limits"};
  for (const tuning::TuneResult::Candidate& k : c.result.scan) {
    t.rows.push_back({num(c.to_hz(k.omega_star)), num(k.omega_star, 4), yes_no(k.stable),
                      k.stable ? num(c.to_hz(k.bandwidth)) : "-", k.stable ? num(k.peak_s, 4) : "-",
                      k.stable ? num(k.peak_tracking, 4) : "-", yes_no(k.feasible)});
  }
  return t;
}

/// The automatic scan of the full-order knob: kbw (lqg) or w0S (hinf).
Table knob_scan_table(const Context& c, const std::string& knob) {
  Table t;
  t.title = "Automatic " + knob + " scan";
  t.header = {knob, "stable", "bandwidth [Hz]", "‖S‖∞", "tracking peak", "within the limits"};
  for (const tuning::TuneResult::Candidate& k : c.result.scan) {
    t.rows.push_back({num(k.omega_star, 4), yes_no(k.stable), k.stable ? num(c.to_hz(k.bandwidth)) : "-",
                      k.stable ? num(k.peak_s, 4) : "-", k.stable ? num(k.peak_tracking, 4) : "-", yes_no(k.feasible)});
  }
  return t;
}

/// One row per real pole and per complex pair (upper member), by increasing modulus.
Table poles_table(const Context& c) {
  std::vector<Complex> poles;
  for (const Complex& p : c.controller.predicted.closed_loop_poles)
    if (p.imag() >= 0.0) poles.push_back(p);
  std::sort(poles.begin(), poles.end(), [](Complex a, Complex b) { return std::abs(a) < std::abs(b); });
  Table t;
  t.title = "Closed-loop poles (with the known HF dynamics; a delay enters as its Padé approximant)";
  t.header = {"|p| [Hz]", "damping", "real part [1/s]", "imaginary part [Hz]", "kind"};
  for (const Complex& p : poles) {
    const double modulus = std::abs(p);
    t.rows.push_back({num(c.to_hz(modulus)), modulus > 0.0 ? num(-p.real() / modulus, 4) : "-",
                      num(p.real() * c.plant.omega_z), num(c.to_hz(p.imag())),
                      p.imag() > 0.0 ? "complex pair" : "real"});
  }
  return t;
}

/// The rows every full-order design shows: its states, its own stability, its poles (one row per
/// real pole and per pair, with their frequency) and the discretization; `name` is what the
/// design calls it ("compensator", "controller").
void add_compensator_rows(Table& t, const Context& c, const tuning::FullOrderSummary& f, const std::string& name,
                          const std::string& states_note) {
  t.rows.push_back({name + " states", std::to_string(f.compensator.states()), states_note});
  t.rows.push_back({name, f.controller_stable ? "stable" : "UNSTABLE", "stable only inside the closed loop when unstable"});
  for (const Complex& p : f.controller_poles) {
    if (p.imag() < 0.0) continue;
    t.rows.push_back({name + " pole", fmt::format("{} {} {}j", num(p.real(), 4), p.imag() > 0.0 ? "±" : "+", num(p.imag(), 4)),
                      fmt::format("{} Hz", num(c.to_hz(std::abs(p)), 4))});
  }
  if (c.controller.discrete)
    t.rows.push_back({"discretized (Tustin) at ts", num(c.controller.discrete->ts * 1e3, 5) + " ms", ""});
}

Table lqg_table(const Context& c) {
  const tuning::FullOrderSummary& f = *c.controller.full_order;
  const tuning::VelocityLqgOptions& w = f.weights;
  Table t;
  t.title = "LQG design (C7.13, normalized weights)";
  t.header = {"parameter", "value", "note"};
  t.rows.push_back({"kbw", num(w.kbw, 5), f.kbw_source});
  t.rows.push_back({"feedforward kff", num(w.feedforward, 5),
                    fmt::format("{} torque per velocity (model units); {}", num(w.feedforward * c.torque_per_velocity(), 5),
                                f.feedforward_source)});
  const double cc = c.plant.r * c.plant.r / 2.0;
  t.rows.push_back({"control weight ρ = kbw/c², c = r²/2", num(w.kbw / (cc * cc), 5), "also the Q weight of the shaft torque"});
  t.rows.push_back({"Q weight of ωl, of the integral", num(w.q_load_velocity, 4) + ", " + num(w.q_integral, 4), ""});
  t.rows.push_back({"process noise into ωm, into Tl", num(w.noise_motor, 4) + ", " + num(w.noise_load_torque, 4), ""});
  t.rows.push_back({"measurement noise V", num(w.measurement_noise, 4), ""});
  t.rows.push_back({"motor velocity fed back", w.raw_motor_velocity ? "measured" : "estimated", ""});
  add_compensator_rows(t, c, f, "compensator", "");
  return t;
}

Section lqg_design_section(const Context& c) {
  const tuning::Controller& k = c.controller;
  Section s;
  s.title = "Design";
  s.text = fmt::format(
      "Full-order velocity LQG (C7.13) on the first mode's two-mass realization: regulator on [ωm, ωl, Ts, ∫(ω* − ωm)], "
      "Kalman filter on [ωm, ωl, Ts, Tl] from the motor velocity; kbw = {} ({}). Larger kbw makes control dearer "
      "and the loop slower.",
      num(k.full_order->weights.kbw, 4), k.full_order->kbw_source);
  if (!c.result.scan.empty())
    s.text += fmt::format(" The scan evaluated {} values of kbw from 1e3 (slow) to 1e-4 (fast), the boundary refined "
                          "by bisection.",
                          c.result.scan.size());
  for (const std::string& note : k.notes) s.text += "\n\nNote: " + note;
  s.tables.push_back(lqg_table(c));
  if (!c.result.scan.empty()) s.tables.push_back(knob_scan_table(c, "kbw"));
  s.tables.push_back(poles_table(c));
  return s;
}

Table hinf_table(const Context& c) {
  const tuning::FullOrderSummary& f = *c.controller.full_order;
  const tuning::HinfSummary& h = *f.hinf;
  Table t;
  t.title = "H∞ mixed-sensitivity design (C7.14, normalized weights)";
  t.header = {"parameter", "value", "note"};
  t.rows.push_back({"ω0S / ωz", num(h.omega_0s, 5), fmt::format("{} Hz; {}", num(c.to_hz(h.omega_0s), 4), h.omega_0s_source)});
  t.rows.push_back({"ω0T / ωz", num(h.omega_0t, 5), "bandwidth cap of W2"});
  t.rows.push_back({"ξv", num(h.xi_v, 4), "damping the resonant pair is moved to"});
  t.rows.push_back({"γ (optimum)", num(h.gamma_optimal, 5), "sup √(|W1 S V|² + |W2 U V|²) of the best controller"});
  t.rows.push_back({"γ of the controller", num(h.gamma, 5), "1 % above the optimum: a well-conditioned central controller"});
  add_compensator_rows(t, c, f, "controller", "K = K0/s (integral action)");
  return t;
}

Section hinf_design_section(const Context& c) {
  const tuning::Controller& k = c.controller;
  Section s;
  s.title = "Design";
  s.text = fmt::format(
      "H∞ mixed-sensitivity velocity controller (C7.14) on the first mode's plant Pe = Pm/s: W1 = 1/Ms, W2 = (1/Mt)"
      "(s + ω0T)²(s + r)²/[(s + ω0S)²(s² + 2ξv r s + r²)(ω0T r)²] and the pole-relocating V = (s + ω0S)²(s² + 2ξv r s + "
      "r²)/den(Pe), so that the controller damps the resonance instead of notching it; ω0S = {} ωz ({}).",
      num(k.full_order->hinf->omega_0s, 4), k.full_order->hinf->omega_0s_source);
  if (!c.result.scan.empty())
    s.text += fmt::format(" The search evaluated {} values of ω0S from 0.05 ωz to 2r ωz, each with the first ω0T of r, 2r, "
                          "4r, 8r that met the spec, the boundary refined by bisection.",
                          c.result.scan.size());
  for (const std::string& note : k.notes) s.text += "\n\nNote: " + note;
  s.tables.push_back(hinf_table(c));
  if (!c.result.scan.empty()) s.tables.push_back(knob_scan_table(c, "ω0S/ωz"));
  s.tables.push_back(poles_table(c));
  return s;
}

Section design_section(const Context& c, bool load) {
  const tuning::Controller& k = c.controller;
  if (k.full_order && k.full_order->hinf) return hinf_design_section(c);
  if (k.full_order) return lqg_design_section(c);
  Section s;
  s.title = "Design";
  s.text = fmt::format(
      "Structure {}: the pair s^2 + 2 ζ* ω* s + ω*^2 is assigned with ω* = {} Hz ({} ωz) and ζ* = {}; ω* {}.",
      tuning::to_string(k.structure), num(c.to_hz(k.design.omega_star)), num(k.design.omega_star, 4),
      num(k.design.zeta_star, 3),
      k.design.omega_star_source == "given" ? "was given" : "was chosen automatically: " + k.design.omega_star_source);
  if (!c.result.scan.empty())
    s.text += fmt::format(
        " The scan evaluated {} candidates on the admissible range (the chosen ω* is refined between "
        "the best candidate within the limits and the next one).",
        c.result.scan.size());
  for (const std::string& note : k.notes) s.text += "\n\nNote: " + note;
  s.tables.push_back(design_table(c));
  s.tables.push_back(gains_table(c));
  if (!c.result.scan.empty()) {
    s.tables.push_back(scan_table(c));
    s.charts = scan_charts(c, load);
  }
  s.tables.push_back(poles_table(c));
  return s;
}

// ---------------------------------------------------------------- 3. loop shapes

Table margins_table(const Context& c) {
  const tuning::LoopIndices& i = c.controller.predicted;
  Table t;
  t.title = "Margins and peaks (with the known HF dynamics)";
  t.header = {"index", "value", "unit / where"};
  t.rows.push_back({"closed loop stable", yes_no(i.closed_loop_stable), ""});
  t.rows.push_back(
      {"gain margin", num(i.gain_margin_db, 4), fmt::format("dB at {} Hz", num(c.to_hz(i.phase_crossover)))});
  t.rows.push_back(
      {"phase margin", num(i.phase_margin_deg, 4), fmt::format("deg at {} Hz", num(c.to_hz(i.gain_crossover)))});
  t.rows.push_back({"modulus margin 1/‖S‖∞", num(i.modulus_margin, 4), ""});
  t.rows.push_back({"‖S‖∞", num(i.peak_s, 4), fmt::format("at {} Hz", num(c.to_hz(i.peak_s_omega)))});
  t.rows.push_back({"‖T‖∞", num(i.peak_t, 4), ""});
  const std::string v = c.variable();
  const char* quantity = c.position() ? "position" : "velocity";
  t.rows.push_back({fmt::format("‖{0}m/{0}*‖∞", v), num(i.peak_tm, 4), ""});
  t.rows.push_back({fmt::format("‖{0}l/{0}*‖∞", v), num(i.peak_tl, 4), c.position() ? "with the prefilter" : ""});
  t.rows.push_back({fmt::format("‖{}l/Tl‖∞ (closed loop)", v), num(i.peak_load_disturbance * c.output_per_torque(), 4),
                    fmt::format("{} per torque (model units)", quantity)});
  t.rows.push_back({"J2 = ‖(ωl/Tl) W‖∞ closed/open loop", num(i.j2, 4), "W = s/(s + ωz)"});
  t.rows.push_back({fmt::format("motor {} bandwidth", quantity), num(c.to_hz(i.bandwidth_motor)),
                    fmt::format("Hz (−3 dB of {0}m/{0}*)", v)});
  t.rows.push_back({fmt::format("load {} bandwidth", quantity), num(c.to_hz(i.bandwidth_load)),
                    fmt::format("Hz (−3 dB of {0}l/{0}*)", v)});
  t.rows.push_back({"controller gain at high frequency", num(i.hf_controller_gain * c.torque_per_velocity()),
                    fmt::format("torque per velocity at {} Hz (noise amplification)", num(c.to_hz(10.0 * c.plant.r)))});
  t.rows.push_back({"least closed-loop damping", num(i.min_damping, 4), ""});
  return t;
}

std::vector<Chart> loop_charts(const Context& c, const tuning::VelocityLoop& loop) {
  const std::size_t n = c.omega.size();
  std::vector<Complex> s(n), t(n), tm(n), tl(n), dist(n), dist_open(n), ctrl(n);
  for (std::size_t k = 0; k < n; ++k) {
    const tuning::VelocityLoop::Responses r = loop.responses(c.omega[k]);
    // A position controller's outputs are positions: the velocity form's over jω.
    const Complex to_output = c.position() ? 1.0 / Complex(0.0, c.omega[k]) : Complex(1.0, 0.0);
    s[k] = r.sensitivity;
    t[k] = r.complementary;
    tm[k] = r.motor_tracking * to_output;
    tl[k] = r.load_tracking * to_output;
    dist[k] = r.load_from_load_torque * to_output;
    dist_open[k] = r.open_loop_load_from_load_torque * to_output;
    ctrl[k] = loop.controller(c.omega[k]);
  }
  const tuning::DesignParameters& d = c.controller.design;
  const std::string v = c.variable();
  Chart shapes = frequency_chart("Sensitivity and tracking", "magnitude [dB]");
  shapes.series.push_back({"|S|", c.hz, db_of(s)});
  shapes.series.push_back({"|T|", c.hz, db_of(t)});
  shapes.series.push_back({fmt::format("|{0}m/{0}*|", v), c.hz, db_of(tm)});
  if (loop.has_load_tracking()) shapes.series.push_back({fmt::format("|{0}l/{0}*|", v), c.hz, db_of(tl)});
  if (d.ms) shapes.series.push_back(flat(fmt::format("Ms = {}", num(*d.ms, 3)), c.hz, db(*d.ms)));
  if (d.mt) shapes.series.push_back(flat(fmt::format("Mt = {}", num(*d.mt, 3)), c.hz, db(*d.mt)));
  std::vector<Chart> charts{std::move(shapes)};
  if (loop.has_load()) {
    Chart disturbance = frequency_chart(fmt::format("Load-torque disturbance |{}l/Tl|", v),
                                        fmt::format("magnitude [dB, {} per torque]", c.position() ? "position" : "velocity"));
    disturbance.series.push_back({"closed loop", c.hz, db_of(dist, c.output_per_torque())});
    disturbance.series.push_back({"open loop (no control)", c.hz, db_of(dist_open, c.output_per_torque())});
    charts.push_back(std::move(disturbance));
  }
  Chart controller = frequency_chart("Controller |C(jω)|", "magnitude [dB, torque per velocity]");
  controller.series.push_back({"|C|", c.hz, db_of(ctrl, c.torque_per_velocity())});
  charts.push_back(std::move(controller));
  return charts;
}

Section loop_section(const Context& c, const tuning::VelocityLoop& loop) {
  Section s;
  s.title = "Loop shapes";
  s.text =
      "Frequency functions of the velocity loop evaluated with the higher modes and the known HF dynamics (a "
      "delay exactly as e^(-jωT)): S = 1/(1 + L), T = L/(1 + L), the motor and load velocity per velocity "
      "reference, the load velocity per load torque (closed loop against the uncontrolled plant: J2's "
      "reference) and the feedback controller C(s). Peaks and margins are the analysis' values (grid plus "
      "refinement).";
  if (tuning::measures_both(c.controller.structure))
    s.text += " The controller measures BOTH velocities (C7.17's LQG): L = (Cm·Pm + Cl·Pl), broken at the torque, so "
              "S, T and the margins are those of that one loop; C(s) is the motor channel Cm.";
  else if (tuning::measures_load(c.controller.structure))
    s.text += " The controller measures the LOAD velocity (C7.17): L = C·Pl, so S, T and the margins are those of the "
              "load loop; the load-torque response of ωl is its open-loop one times S.";
  if (c.position())
    s.text += " This is a position controller (inputs φ* and φm): the loop is analysed in its velocity form (the "
              "feedback C2/s on ωm), so S, T, the margins and C are the position loop's, and the tracking and "
              "disturbance functions are positions (φm/φ*, φl/φ* with the reference prefilter, φl/Tl).";
  if (!loop.has_load_tracking())
    s.text += " The plant has higher modes or no two-mass realization (its shaft damping would be negative): no "
              "load-side functions.";
  else if (!loop.has_load())
    s.text += " The higher modes are read as couplings of the drive train (--load-side chain): the load tracking "
              "is an estimate and there are no load-torque functions.";
  s.tables.push_back(margins_table(c));
  s.charts = loop_charts(c, loop);
  return s;
}

// ---------------------------------------------------------------- 4. robustness

Section robustness_section(const Context& c, const tuning::VelocityLoop& loop,
                           const std::optional<core::TransferFunction>& w2n) {
  Section s;
  s.title = "Robustness";
  if (!w2n) {
    s.text =
        "No uncertainty weight W2 was given (servotwin tune --w2-num/--w2-den or --w2-from-frf): robust "
        "stability and performance were not evaluated.";
    return s;
  }
  const double ms = c.controller.design.ms.value_or(std::numeric_limits<double>::infinity());
  const bool with_ms = c.controller.design.ms.has_value();
  const tuning::RobustnessResult rob = tuning::robustness(loop, *w2n, with_ms ? ms : 2.0);
  s.text =
      "Multiplicative uncertainty P = Pn (1 + Δ W2), ‖Δ‖∞ < 1 (catalog C7.9): robust stability (RS) iff "
      "‖W2 T‖∞ < 1, nominal performance (NP) iff ‖S‖∞/Ms < 1, robust performance (RP) iff sup(|S|/Ms + |W2 T|) "
      "< 1, i.e. the curves below stay under the line 1 (0 dB).";
  Table t;
  t.title = "Robust stability and performance";
  t.header = {"test", "value", "at [Hz]", "passes"};
  t.rows.push_back({"RS: ‖W2 T‖∞", num(rob.rs, 5), num(c.to_hz(rob.rs_omega)), yes_no(rob.rs_ok)});
  if (with_ms) {
    t.rows.push_back({"NP: ‖S‖∞/Ms", num(rob.np, 5), num(c.to_hz(rob.np_omega)), yes_no(rob.np_ok)});
    t.rows.push_back({"RP: sup(|S|/Ms + |W2 T|)", num(rob.rp, 5), num(c.to_hz(rob.rp_omega)), yes_no(rob.rp_ok)});
  }
  if (const std::optional<double> mt = c.controller.design.mt; mt && !c.position()) {
    const tuning::RobustTracking rt = tuning::robust_tracking(loop, *w2n, *mt);
    t.rows.push_back({"robust tracking (C7.13): sup |ωm/ω*|(1 + |W2|)/(1 − |W2 T|)/Mt", num(rt.value, 5),
                      num(c.to_hz(rt.omega)), yes_no(rt.ok())});
  }
  s.tables.push_back(std::move(t));

  const std::size_t n = c.omega.size();
  std::vector<Complex> w(n), wt(n);
  std::vector<double> rp(n);
  for (std::size_t k = 0; k < n; ++k) {
    w[k] = w2n->frequency_response(c.omega[k]);
    wt[k] = w[k] * loop.complementary(c.omega[k]);
    rp[k] = db(std::abs(loop.sensitivity(c.omega[k])) / ms + std::abs(wt[k]));
  }
  Chart chart = frequency_chart("Robustness against W2", "magnitude [dB]");
  chart.series.push_back({"|W2|", c.hz, db_of(w)});
  chart.series.push_back({"|W2 T| (RS)", c.hz, db_of(wt)});
  if (with_ms) chart.series.push_back({"|S|/Ms + |W2 T| (RP)", c.hz, rp});
  chart.series.push_back(flat("1", c.hz, 0.0));
  s.charts.push_back(std::move(chart));
  return s;
}

// ---------------------------------------------------------------- 4b. position loop

/// The velocity loop the position loop was designed on (tune.cpp: the loop itself when it has a
/// load side, else the first mode's two-mass loop).
tuning::VelocityLoop position_base(const Context& c, const tuning::VelocityLoop& loop) {
  if (loop.has_load()) return loop;
  return tuning::controller_loop(c.plant, c.controller, true, false);
}

Section position_section(const Context& c, const tuning::VelocityLoop& base,
                         const std::optional<core::TransferFunction>& w2n) {
  const tuning::PositionSummary& p = *c.controller.position;
  const double kpp = *c.controller.kpp_normalized;
  Section s;
  s.title = "Position loop";
  s.text = fmt::format(
      "A P position loop ω* = Kpp (φ* − φm) over the velocity loop (catalog C7.10) with Kpp = {} 1/s ({} ωz): the "
      "largest gain that keeps the load position free of overshoot (‖φl/φ*‖∞ <= 1){}.",
      num(kpp * c.plant.omega_z), num(kpp, 4), w2n ? ", lowered to the robust limits of W2" : "");
  const auto scale = [&](std::optional<double> v) { return v ? num(*v * c.plant.omega_z) : std::string("-"); };
  const auto normalized = [&](std::optional<double> v) { return v ? num(*v) : std::string("-"); };
  Table t;
  t.title = "Position gain limits";
  t.header = {"limit", "Kpp [1/s]", "Kpp/ωz"};
  t.rows.push_back({"no overshoot of the load position", scale(p.kpp_nominal), normalized(p.kpp_nominal)});
  t.rows.push_back({"robust stability (W2)", scale(p.kpp_rs), normalized(p.kpp_rs)});
  t.rows.push_back({"robust performance, exact worst case (W2)", scale(p.kpp_rp_exact), normalized(p.kpp_rp_exact)});
  t.rows.push_back({"chosen", scale(kpp), normalized(kpp)});
  s.tables.push_back(std::move(t));
  Table i;
  i.title = "Position loop at the chosen Kpp";
  i.header = {"index", "value", "unit"};
  i.rows.push_back({"load position bandwidth", num(c.to_hz(p.bandwidth_load)), "Hz (−3 dB of φl/φ*)"});
  i.rows.push_back({"‖φl/φ*‖∞", num(p.peak_load_tracking, 5), ""});
  i.rows.push_back({"‖φl/Tl‖∞", num(p.j2 * c.position_per_torque(), 5), "position per torque (model units)"});
  s.tables.push_back(std::move(i));

  const tuning::PositionLoop position(tuning::functions_of(base), w2n);
  const std::size_t n = c.omega.size();
  std::vector<Complex> load(n), motor(n), dist(n);
  for (std::size_t k = 0; k < n; ++k) {
    load[k] = position.load_tracking(c.omega[k], kpp);
    motor[k] = position.motor_tracking(c.omega[k], kpp);
    dist[k] = position.load_from_load_torque(c.omega[k], kpp);
  }
  Chart tracking = frequency_chart("Position tracking", "magnitude [dB]");
  tracking.series.push_back({"|φl/φ*|", c.hz, db_of(load)});
  tracking.series.push_back({"|φm/φ*|", c.hz, db_of(motor)});
  tracking.series.push_back(flat("1", c.hz, 0.0));
  Chart disturbance = frequency_chart("Load-torque disturbance |φl/Tl|", "magnitude [dB, position per torque]");
  disturbance.series.push_back({"|φl/Tl|", c.hz, db_of(dist, c.position_per_torque())});
  s.charts = {std::move(tracking), std::move(disturbance)};
  return s;
}

// ---------------------------------------------------------------- 5. time responses

Section time_section(const Context& c, const tuning::VelocityLoop& loop,
                     const tuning::VelocityLoop& position_base_loop) {
  Section s;
  s.title = "Time responses (linear)";
  const tuning::LoopIndices& i = c.controller.predicted;
  if (!i.closed_loop_stable) {
    s.text = "The closed loop is unstable: no step responses.";
    return s;
  }
  s.text =
      "Unit steps of the LINEAR closed loop (the rational transfer functions with the higher modes and the known "
      "HF dynamics, a delay as its Padé approximant), simulated by exact zero-order hold as the analysis does: the "
      "samples are exact. Torque saturation, Coulomb friction, backlash and the drive's sampling are not in these "
      "responses: they are linear predictions only.";
  const TimeGrid g = time_grid(i.horizon, i.sample_time, c.options.time_points);
  std::vector<double> t(g.samples);
  for (std::size_t k = 0; k < g.samples; ++k) t[k] = c.to_seconds(static_cast<double>(k) * g.dt);
  const tuning::ClosedLoopTransfer cl =
      c.position() ? tuning::integrated_outputs(loop.closed_loop()) : loop.closed_loop();
  const std::string quantity = c.position() ? "position" : "velocity";
  const std::string v = c.variable();

  Chart velocity;
  velocity.title = (c.position() ? "Position" : "Velocity") + std::string(" setpoint step");
  velocity.x_label = "time [s]";
  velocity.y_label = quantity + " (unit step)";
  velocity.series.push_back({"motor " + quantity + " " + v + "m", t, core::step_response(cl.motor_tracking, g.dt, g.samples)});
  if (cl.load_tracking)
    velocity.series.push_back(
        {"load " + quantity + " " + v + "l", t, core::step_response(*cl.load_tracking, g.dt, g.samples)});
  Chart torque;
  torque.title = "Torque command for the " + quantity + " setpoint step (per unit " + quantity + ")";
  torque.x_label = "time [s]";
  torque.y_label = "torque [model units]";
  torque.series.push_back(
      {"torque command u", t, scaled(core::step_response(cl.effort, g.dt, g.samples), c.torque_per_reference())});
  s.charts = {std::move(velocity), std::move(torque)};
  if (cl.load_from_load_torque && cl.motor_from_load_torque) {
    Chart disturbance;
    disturbance.title = "Load-torque step (per unit torque)";
    disturbance.x_label = "time [s]";
    disturbance.y_label = quantity + " [model units]";
    disturbance.series.push_back(
        {"load " + quantity + " " + v + "l", t,
         scaled(core::step_response(*cl.load_from_load_torque, g.dt, g.samples), c.output_per_torque())});
    disturbance.series.push_back(
        {"motor " + quantity + " " + v + "m", t,
         scaled(core::step_response(*cl.motor_from_load_torque, g.dt, g.samples), c.output_per_torque())});
    s.charts.push_back(std::move(disturbance));
  }
  if (c.controller.kpp_normalized) {
    const tuning::PositionClosedLoop p =
        tuning::position_closed_loop(position_base_loop.closed_loop(), *c.controller.kpp_normalized);
    std::vector<Complex> poles = p.characteristic.roots();
    double slowest = std::numeric_limits<double>::infinity(), fastest = 0.0;
    for (const Complex& z : poles) {
      slowest = std::min(slowest, -z.real());
      fastest = std::max(fastest, std::abs(z));
    }
    if (slowest > 0.0 && std::isfinite(slowest)) {
      // The analysis' rule (loop_analysis.hpp) on the cascade's poles.
      const TimeGrid pg =
          time_grid(kHorizonTimeConstants / slowest, kStepPerFastestPole / fastest, c.options.time_points);
      std::vector<double> tp(pg.samples);
      for (std::size_t k = 0; k < pg.samples; ++k) tp[k] = c.to_seconds(static_cast<double>(k) * pg.dt);
      Chart position;
      position.title = "Position setpoint step (P position loop)";
      position.x_label = "time [s]";
      position.y_label = "position (unit step)";
      position.series.push_back({"load position φl", tp, core::step_response(p.load_tracking, pg.dt, pg.samples)});
      position.series.push_back({"motor position φm", tp, core::step_response(p.motor_tracking, pg.dt, pg.samples)});
      s.charts.push_back(std::move(position));
    }
  }
  return s;
}

void check_options(const TuningReportOptions& o) { detail::check_point_counts(o.frequency_points, o.time_points, kMinPoints); }

}  // namespace

Document tuning_report(const tuning::TuneResult& result, const TuningReportOptions& options) {
  check_options(options);
  const tuning::NormalizedPlant& plant = result.plant;
  std::optional<core::TransferFunction> w2n;
  if (options.w2) w2n = tuning::to_normalized_time(*options.w2, plant.omega_z);
  Context c{result, options, plant, result.controller, frequency_grid(result, options.frequency_points), {}};
  c.hz.reserve(c.omega.size());
  for (double w : c.omega) c.hz.push_back(c.to_hz(w));

  const tuning::VelocityLoop loop = tuning::controller_loop(plant, result.controller);
  Document doc;
  doc.title = "servotwin tune: " + tuning::to_string(result.controller.structure) + " controller";
  const auto& f = result.controller.full_order;
  doc.subtitle = fmt::format("{}{}antiresonance {} Hz, r = {}, {}", options.source, options.source.empty() ? "" : ": ",
                             num(c.to_hz(1.0), 4), num(plant.r, 4),
                             f && f->hinf ? fmt::format("ω0S = {} Hz, γ = {}", num(c.to_hz(f->hinf->omega_0s), 4),
                                                        num(f->hinf->gamma, 4))
                             : f ? fmt::format("kbw = {}", num(f->position_weights ? f->position_weights->kbw : f->weights.kbw, 4))
                                 : fmt::format("ω* = {} Hz", num(c.to_hz(result.controller.design.omega_star), 4)));
  doc.sections.push_back(plant_section(c));
  doc.sections.push_back(design_section(c, loop.has_load_tracking()));
  doc.sections.push_back(loop_section(c, loop));
  doc.sections.push_back(robustness_section(c, loop, w2n));
  const tuning::VelocityLoop base = position_base(c, loop);
  if (result.controller.position && result.controller.kpp_normalized)
    doc.sections.push_back(position_section(c, base, w2n));
  doc.sections.push_back(time_section(c, loop, base));
  for (const vcnc::DriveSimulation& sim : options.simulations)
    doc.sections.push_back(drive_section(sim, fmt::format("Simulation on the plant: {}", vcnc::to_string(sim.test))));
  return doc;
}

}  // namespace servotwin::report
