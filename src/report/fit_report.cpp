#include "servotwin/report/fit_report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <optional>
#include <vector>

#include "bode.hpp"
#include "chart_helpers.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "number_format.hpp"

namespace servotwin::report {

namespace {

using detail::magnitude_db;
using detail::unwrapped_phase_deg;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr std::size_t kModelPoints = 1200;

std::string num(double v, int digits = 6) { return detail::format_number(v, digits); }

/// "value ± std" with the std omitted when it is not identifiable.
std::string with_std(double value, double std_dev, double scale = 1.0) {
  if (!std::isfinite(value)) return "-";
  if (!std::isfinite(std_dev)) return num(value * scale);
  return fmt::format("{} ± {}", num(value * scale), num(std_dev * scale, 2));
}

std::string with_std(const fit::Estimate& e, double scale = 1.0) { return with_std(e.value, e.std, scale); }

/// A two-column table: a name and its value per row.
Table value_table(std::string title, std::string name_header, std::vector<std::vector<std::string>> rows) {
  Table t;
  t.title = std::move(title);
  t.header = {std::move(name_header), "value"};
  t.rows = std::move(rows);
  return t;
}

Section model_section(const fit::FitReport& report) {
  const fit::FitResult& r = report.result;
  const fit::PlantModel& m = r.model;
  Section s;
  s.title = "Fitted model";
  s.text = fmt::format(
      "Model {} with {} flexible mode(s) measured on the {} side, {} output ({}), rigid part {}{}{}. Fitted by "
      "Levenberg-Marquardt on the log-relative complex error ({} weighting) from the {} start: {}.",
      fit::to_string(report.request), m.modes.size(), fit::to_string(m.sensor), fit::to_string(m.output), report.output.note.empty() ? "as asked" : report.output.note,
      m.rigid == fit::RigidKind::kIntegrator ? "K/s" : "K/(s + a)", m.lag_pole_rad_s ? ", extra lag 1/(s + tau2)" : "",
      m.delay_s ? ", delay e^(-sT)" : "", r.weighting, r.initialization, r.message);
  Table t;
  t.title = "Parameters";
  t.header = {"parameter", "value", "unit"};
  t.rows.push_back({"gain K", with_std(r.gain), "output/input x rad/s"});
  if (m.rigid == fit::RigidKind::kRealPole) t.rows.push_back({"rigid pole a", with_std(r.rigid_pole_rad_s, 1.0 / kTwoPi), "Hz"});
  if (m.lag_pole_rad_s) t.rows.push_back({"lag pole tau2", with_std(r.lag_pole_rad_s, 1.0 / kTwoPi), "Hz"});
  if (m.delay_s) t.rows.push_back({"delay T", with_std(r.delay_s, 1e3), "ms"});
  t.rows.push_back({"points", std::to_string(r.points), ""});
  t.rows.push_back({"free parameters", std::to_string(r.parameters), ""});
  t.rows.push_back({"iterations", std::to_string(r.iterations), ""});
  t.rows.push_back({"rms |ln(P_model/P_meas)|", num(r.rms_log_error, 4), "(0.01 = 1 %)"});
  s.tables.push_back(std::move(t));
  if (!r.uncertainty_note.empty()) s.text += " Uncertainty: " + r.uncertainty_note + ".";
  if (!report.left_out.empty()) {
    // Issue 25 §1: what the measurement marked invalid and the fit therefore did not use.
    Table left;
    left.title = "Points left out (marked invalid by the measurement, or outliers of the first fit)";
    left.header = {"frequency", "why"};
    for (const std::string& line : report.left_out) {
      const std::size_t colon = line.find(": ");
      left.rows.push_back({line.substr(0, colon), colon == std::string::npos ? "" : line.substr(colon + 2)});
    }
    s.tables.push_back(std::move(left));
  }
  return s;
}

Section modes_section(const fit::FitReport& report) {
  const fit::FitResult& r = report.result;
  Section s;
  s.title = "Modes";
  s.text = r.model.sensor == fit::SensorSide::kMotor
               ? "Antiresonance (zeros) and resonance (poles) of each flexible mode, with one standard deviation from "
                 "the Jacobian of the fit."
               : "Resonance (poles) of each flexible mode of a load-side response, which has no antiresonance (each "
                 "mode's zero is the shaft's damping, 2 zeta w s + w^2), with one standard deviation from the Jacobian "
                 "of the fit.";
  Table t;
  t.title = "Modes";
  t.header = {"mode", "antiresonance [Hz]", "zeta", "resonance [Hz]", "zeta", "ratio r"};
  for (std::size_t i = 0; i < r.model.modes.size(); ++i) {
    const fit::Mode& mode = r.model.modes[i];
    std::vector<std::string> row{std::to_string(i + 1)};
    if (i < r.mode_estimates.size()) {
      const fit::ModeUncertainty& u = r.mode_estimates[i];
      row.insert(row.end(), {with_std(u.antiresonance_omega, 1.0 / kTwoPi), with_std(u.antiresonance_zeta),
                             with_std(u.resonance_omega, 1.0 / kTwoPi), with_std(u.resonance_zeta)});
    } else {
      row.insert(row.end(), {num(mode.antiresonance.omega_rad_s / kTwoPi), num(mode.antiresonance.zeta),
                             num(mode.resonance.omega_rad_s / kTwoPi), num(mode.resonance.zeta)});
    }
    row.push_back(r.model.sensor == fit::SensorSide::kMotor ? num(mode.resonance.omega_rad_s / mode.antiresonance.omega_rad_s, 4)
                                                            : "-");
    t.rows.push_back(std::move(row));
  }
  if (t.rows.empty()) s.text = "The model has no flexible mode (rigid body only).";
  else s.tables.push_back(std::move(t));
  return s;
}

Section physical_section(const fit::FitReport& report) {
  const fit::PhysicalExtraction& p = report.result.physical;
  Section s;
  s.title = "Physical parameters";
  if (!p.parameters) {
    s.text = p.note.empty() ? "No two-mass reading of this model." : p.note;
    return s;
  }
  const fit::TwoMassParameters& q = *p.parameters;
  s.text = "Two-mass reading of the one-mode model (C3.12): Im = 1/K (tau2/K with a lag), Il = Im (r^2 - 1), k = Il wz^2, "
           "b = 2 zeta_z wz Il; " + p.note + ". Units follow the data (torque in N m and velocity in rad/s give kg m^2, N m/rad, N m s/rad).";
  s.tables.push_back(value_table("Two-mass parameters", "parameter",
                                 {{"motor inertia Im", with_std(q.motor_inertia)},
                                  {"load inertia Il", with_std(q.load_inertia)},
                                  {"shaft stiffness k", with_std(q.stiffness)},
                                  {"shaft damping b", with_std(q.damping)},
                                  {"resonance ratio r", with_std(q.resonance_ratio)},
                                  {"damping consistency zeta_n/(r zeta_z)", num(q.damping_consistency, 4)}}));
  return s;
}

Section selection_section(const fit::FitReport& report) {
  Section s;
  s.title = "Model order";
  s.text = fmt::format("Selection {}: {}. Chosen: {} mode(s).", report.selection.method, report.selection.criterion,
                       report.selection.chosen);
  Table t;
  t.title = "Candidates";
  t.header = {"modes", "parameters", "converged", "cost", "score"};
  for (const auto& c : report.selection.candidates)
    t.rows.push_back({std::to_string(c.modes), std::to_string(c.parameters), c.converged ? "yes" : "no: " + c.message,
                      num(c.cost), num(c.score)});
  if (!t.rows.empty()) s.tables.push_back(std::move(t));
  return s;
}

Section nonlinear_section(const fit::NonlinearMechanics& n) {
  Section s;
  s.title = "Nonlinear mechanics";
  s.text = "From responses measured at several excitation amplitudes, through the describing functions of Coulomb "
           "friction (4M/(pi V), an extra damping that fades with the velocity amplitude V) and of a dead zone in the "
           "shaft (a softer shaft at small twist: the antiresonance falls). " +
           n.coulomb.note + ". " + n.backlash.note + ".";
  Table t;
  t.title = "Estimates";
  t.header = {"quantity", "value", "significant"};
  if (n.coulomb.estimated)
    t.rows.push_back({"Coulomb friction M (input units)", with_std(n.coulomb.level, n.coulomb.level_std),
                      n.coulomb.significant ? "yes" : "no"});
  if (n.backlash.estimated)
    t.rows.push_back({"backlash width D (position unit of the output: rad for rad/s data)",
                      n.backlash.significant ? num(n.backlash.width, 4) : "none found", n.backlash.significant ? "yes" : "no"});
  if (!t.rows.empty()) s.tables.push_back(std::move(t));
  Table runs;
  runs.title = "Antiresonance per amplitude";
  runs.header = {"excitation amplitude", "antiresonance [Hz]", "shaft stiffness seen", "twist amplitude"};
  for (const auto& r : n.backlash.runs)
    runs.rows.push_back({num(r.amplitude, 4), with_std(r.antiresonance_hz, r.antiresonance_hz_std), num(r.effective_stiffness, 5),
                         num(r.twist_amplitude, 3)});
  if (!runs.rows.empty()) s.tables.push_back(std::move(runs));
  return s;
}

Section friction_section(const fit::CoulombFit& f) {
  Section s;
  s.title = "Coulomb friction";
  s.text = "The mass-chain model with Coulomb friction on motor and load, fitted at each point's measured amplitude "
           "(describing functions 4M/(pi V), harmonic balance). Its linear part (viscous damping only) is the model "
           "above and the one written: " + f.note + ".";
  s.tables.push_back(value_table("Friction and residuals", "quantity",
                                 {{"motor Coulomb friction Mm (input units)", with_std(f.motor_coulomb)},
                                  {"load Coulomb friction Ml (input units)", with_std(f.load_coulomb)},
                                  {"motor viscous damping bv", with_std(f.viscous_damping)},
                                  {"total inertia", with_std(f.total_inertia)},
                                  {"motor's share of the inertia", with_std(f.motor_share)},
                                  {"rms |ln(P_model/P_meas)| with friction", num(f.rms_log_error, 4)},
                                  {"rms |ln(P_model/P_meas)| of the linear fit", num(f.linear_rms_log_error, 4)}}));
  return s;
}

Section response_section(const core::FrequencyResponse& measured, const fit::PlantModel& model,
                         const fit::CoulombFit* friction) {
  Section s;
  s.title = "Frequency response";
  s.text = friction ? "Measured points, the model with Coulomb friction at each measured point (its amplitude) and its "
                      "linear part (delay included) on a dense grid over the measured range; the last chart is the "
                      "relative error of the model with friction at each measured point."
                    : "Measured points and the fitted model (delay included) on a dense grid over the measured range; "
                      "the last chart is the relative error of the model at each measured point.";
  std::vector<double> f_meas, rel_error, rel_std, f_friction;
  std::vector<std::complex<double>> p_meas, p_friction;
  bool any_std = false;
  for (const auto& p : measured.points) {
    f_meas.push_back(p.freq_hz);
    p_meas.push_back(p.value);
    std::complex<double> model_value = model.response(kTwoPi * p.freq_hz);
    if (friction) {
      // Where the friction model has no value (a point without amplitude), the linear model's error.
      const std::complex<double> with_friction = fit::coulomb_response_at(*friction, p);
      if (std::isfinite(with_friction.real())) {
        model_value = with_friction;
        f_friction.push_back(p.freq_hz);
        p_friction.push_back(with_friction);
      }
    }
    rel_error.push_back(std::abs(model_value / p.value - 1.0));
    rel_std.push_back(p.std_dev > 0.0 ? p.std_dev / std::abs(p.value) : std::nan(""));
    any_std = any_std || p.std_dev > 0.0;
  }
  const std::vector<double> f_model = core::log_space(f_meas.front(), f_meas.back(), kModelPoints);
  std::vector<std::complex<double>> p_model(f_model.size());
  for (std::size_t i = 0; i < f_model.size(); ++i) p_model[i] = model.response(kTwoPi * f_model[i]);

  // Unwrap the model on its dense grid; each measured phase goes on the model's branch at its
  // frequency (sparse points far apart cannot be unwrapped among themselves).
  const std::vector<double> model_phase = unwrapped_phase_deg(p_model);
  std::vector<double> measured_phase(p_meas.size());
  for (std::size_t i = 0; i < p_meas.size(); ++i) {
    const auto j = static_cast<std::size_t>(std::lower_bound(f_model.begin(), f_model.end(), f_meas[i]) - f_model.begin());
    const double branch = model_phase[std::min(j, model_phase.size() - 1)];
    const double difference = std::arg(p_meas[i] / model.response(kTwoPi * f_meas[i])) * 180.0 / std::numbers::pi;
    const double model_here = std::arg(model.response(kTwoPi * f_meas[i])) * 180.0 / std::numbers::pi;
    measured_phase[i] = branch + std::remainder(model_here - branch, 360.0) + difference;
  }

  const auto chart = [](std::string title, std::string y_label, Scale y_scale) {
    return detail::frequency_chart(std::move(title), std::move(y_label), y_scale);
  };
  Chart mag = chart("Magnitude", "magnitude [dB]", Scale::Linear);
  mag.series.push_back({"measured", f_meas, magnitude_db(p_meas)});
  const std::string model_name = friction ? "linear part" : "fitted model";
  mag.series.push_back({model_name, f_model, magnitude_db(p_model)});
  Chart phase = chart("Phase", "phase [deg]", Scale::Linear);
  phase.series.push_back({"measured", f_meas, measured_phase});
  phase.series.push_back({model_name, f_model, model_phase});
  if (!f_friction.empty()) {
    mag.series.push_back({"with Coulomb friction", f_friction, magnitude_db(p_friction)});
    std::vector<double> friction_phase;
    for (std::size_t i = 0; i < p_friction.size(); ++i) {
      // On the linear part's branch at that frequency, as the measured phase.
      const auto j = static_cast<std::size_t>(std::lower_bound(f_model.begin(), f_model.end(), f_friction[i]) - f_model.begin());
      const double branch = model_phase[std::min(j, model_phase.size() - 1)];
      friction_phase.push_back(branch + std::remainder(std::arg(p_friction[i]) * 180.0 / std::numbers::pi - branch, 360.0));
    }
    phase.series.push_back({"with Coulomb friction", f_friction, friction_phase});
  }
  Chart error = chart("Relative error of the model", "|P_model/P_meas - 1|", Scale::Log);
  error.series.push_back({"model error", f_meas, rel_error});
  if (any_std) error.series.push_back({"measurement std (relative)", f_meas, rel_std});
  s.charts = {std::move(mag), std::move(phase), std::move(error)};
  return s;
}

}  // namespace

Document fit_report(const core::FrequencyResponse& measured, const fit::FitReport& report, const std::string& source,
                    const fit::NonlinearMechanics* nonlinear, const fit::CoulombFit* friction) {
  if (friction && !friction->fitted) friction = nullptr;
  if (measured.points.empty()) throw core::InputError(core::at_field("points"), "the frequency response has no points");
  Document doc;
  doc.title = "servotwin fit: plant model";
  doc.subtitle = fmt::format("{}: {} points, {:.4g} to {:.4g} Hz{}", source, measured.points.size(),
                             measured.points.front().freq_hz, measured.points.back().freq_hz,
                             measured.duration_s ? fmt::format(", experiment {:.1f} s", *measured.duration_s) : "");
  doc.sections.push_back(model_section(report));
  doc.sections.push_back(modes_section(report));
  doc.sections.push_back(physical_section(report));
  doc.sections.push_back(selection_section(report));
  if (nonlinear) doc.sections.push_back(nonlinear_section(*nonlinear));
  if (friction) doc.sections.push_back(friction_section(*friction));
  doc.sections.push_back(response_section(measured, report.result.model, friction));
  return doc;
}

}  // namespace servotwin::report
