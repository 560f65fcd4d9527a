// The identification report (identification_report.hpp): captures, model, frequency responses
// and the simulated tracking error, as a report::Document.
#include "servotwin/report/identification_report.hpp"

#include "bode.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>

#include "servotwin/core/error.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/rapid/axis_model.hpp"
#include "number_format.hpp"

namespace servotwin::report {

namespace {

using detail::magnitude_db;
using detail::unwrapped_phase_deg;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr std::size_t kFrequencyPoints = 800;

std::string num(double v, int significant = 5) { return detail::format_number(v, significant); }

std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return num(v);
  return fmt::format("{:.{}f}", v, decimals);
}

/// "[mm]" for a unit symbol, "(as in the file)" for a description.
std::string unit_suffix(const std::string& unit) {
  if (unit.empty()) return {};
  return unit.find(' ') == std::string::npos ? "[" + unit + "]" : "(" + unit + ")";
}

std::string joined(const std::vector<std::string>& items, const char* separator = ", ") {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

const core::AxisTrace& require_axis(const vcnc::NamedCapture& c, const std::string& axis) {
  const core::AxisTrace* trace = c.capture.find(axis);
  if (trace == nullptr) {
    throw core::InputError({c.source, 0, 0, "axis"}, "the report needs axis '" + axis + "', which this capture lacks");
  }
  return *trace;
}

std::vector<double> capture_time(const core::Capture& capture) {
  std::vector<double> t(capture.size());
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = capture.time(k);
  return t;
}

std::pair<double, double> value_range(const std::vector<double>& v) {
  if (v.empty()) return {std::nan(""), std::nan("")};
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return {*lo, *hi};
}

struct UsedCapture {
  const vcnc::NamedCapture* capture;
  const char* use;  // "identification" or "validation"
};

std::vector<UsedCapture> all_captures(const std::vector<vcnc::NamedCapture>& captures,
                                      const std::vector<vcnc::NamedCapture>& validation) {
  std::vector<UsedCapture> all;
  for (const auto& c : captures) all.push_back({&c, "identification"});
  for (const auto& c : validation) all.push_back({&c, "validation"});
  return all;
}

// ---- captures ------------------------------------------------------------------------------

Section captures_section(std::span<const vcnc::AxisIdentification> axes, const std::vector<UsedCapture>& used,
                         const std::string& unit) {
  Section s;
  s.title = "Captures";
  s.text = "Commanded position x_r and actual position x of every identified axis, as recorded. The model is "
           "identified from the identification captures; validation captures only score it.";
  Table table;
  table.title = "Captures";
  table.header = {"capture", "use", "samples", "duration [s]", "Ts [ms]"};
  for (const auto& a : axes) {
    table.header.push_back(a.axis + " command range " + unit_suffix(unit));
    table.header.push_back(a.axis + " actual range " + unit_suffix(unit));
  }
  for (const auto& u : used) {
    const core::Capture& c = u.capture->capture;
    std::vector<std::string> row = {u.capture->source, u.use, std::to_string(c.size()),
                                    num(static_cast<double>(c.size() > 0 ? c.size() - 1 : 0) * c.ts, 6),
                                    num(c.ts * 1e3, 6)};
    for (const auto& a : axes) {
      const core::AxisTrace& trace = require_axis(*u.capture, a.axis);
      const auto [cmd_lo, cmd_hi] = value_range(trace.cmd);
      const auto [act_lo, act_hi] = value_range(trace.act);
      row.push_back(num(cmd_lo) + " .. " + num(cmd_hi));
      row.push_back(num(act_lo) + " .. " + num(act_hi));
    }
    table.rows.push_back(std::move(row));
  }
  s.tables.push_back(std::move(table));

  for (const auto& u : used) {
    Chart chart;
    chart.title = u.capture->source + " (" + u.use + "): commanded and actual position";
    chart.x_label = "time [s]";
    chart.y_label = "position " + unit_suffix(unit);
    const std::vector<double> t = capture_time(u.capture->capture);
    for (const auto& a : axes) {
      const core::AxisTrace& trace = require_axis(*u.capture, a.axis);
      chart.series.push_back({a.axis + " command x_r", t, trace.cmd});
      chart.series.push_back({a.axis + " actual x", t, trace.act});
    }
    s.charts.push_back(std::move(chart));
  }
  return s;
}

// ---- model -----------------------------------------------------------------------------------

std::vector<std::string> fit_row(const std::string& what, const rapid::FitMetrics& m) {
  return {what,
          std::to_string(m.samples),
          num(m.rms_measured),
          num(m.rms_predicted),
          num(m.rms_difference),
          num(m.max_difference),
          num(m.nrmse, 4),
          fixed(m.fit_percent, 2)};
}

std::vector<std::string> fit_header(const std::string& first, const std::string& unit) {
  const std::string u = unit_suffix(unit);
  return {first, "samples", "RMS measured " + u, "RMS simulated " + u, "RMS difference " + u,
          "max |difference| " + u, "NRMSE", "fit [%]"};
}

Section model_section(const vcnc::AxisIdentification& id, const rapid::AxisModel& model) {
  const rapid::Solution& sol = id.solution;
  const auto& c = id.coefficients();
  Section s;
  s.title = "Axis " + id.axis + ": model";
  const bool stable = model.is_stable();
  std::string shift;
  if (!id.shift_trials.empty())
    shift = fmt::format(" The command shift of {} samples was chosen by fit from {} candidates (table below).",
                        id.regressors.command_shift, id.shift_trials.size());
  else if (id.regressors.command_shift != 0)
    shift = fmt::format(" The command is shifted by {} samples (x_r,k := cmd[k + {}]).", id.regressors.command_shift,
                        id.regressors.command_shift);
  s.text = fmt::format(
      "Closed-loop axis model of thesis Eq. 3.3, [s^2 + a1 s + a2 + a3/s] x = [b0 s^2 + b1 s + b2 + a3/s] x_r - "
      "[PV(x') d0 + NV(x') d1], identified with the {} solver{} in {} ms. The model is {}; its tracking bandwidth "
      "(-3 dB) is {} Hz.{}",
      rapid::method_name(sol.method), sol.feasible ? "" : " (the solution lies OUTSIDE the bounds)",
      num(sol.time_ms, 3), stable ? "stable" : "UNSTABLE", num(model.bandwidth_hz(), 4), shift);
  if (id.refinement && id.solver_fit && id.fit) {
    s.text += fmt::format(
        " It was then refined by output error (the simulated tracking error fitted to the identification captures "
        "within the same bounds): fit NRMSE {} -> {} in {} iterations, {} ms. The coefficients, roots and responses "
        "below are the refined model's; the solver's model had wn {} Hz, zeta {}, p {} Hz.",
        num(id.solver_fit->nrmse, 4), num(id.fit->nrmse, 4), id.refinement->iterations, num(id.refinement->time_ms, 3),
        num(sol.wn / kTwoPi, 5), num(sol.zeta, 4), num(sol.p / kTwoPi, 5));
  }

  const std::string u = id.length_unit;
  Table coefficients;
  coefficients.title = "Coefficients (thesis Eq. 3.3)";
  coefficients.header = {"coefficient", "value", "unit"};
  coefficients.rows = {{"a1", num(c.a1, 8), "1/s"},       {"a2", num(c.a2, 8), "1/s^2"},
                       {"a3", num(c.a3, 8), "1/s^3"},     {"b0", num(c.b0, 8), "-"},
                       {"b1", num(c.b1, 8), "1/s"},       {"b2", num(c.b2, 8), "1/s^2"},
                       {"d0", num(c.d0, 8), u + "/s^2"},  {"d1", num(c.d1, 8), u + "/s^2"}};
  s.tables.push_back(std::move(coefficients));

  Table solver;
  solver.title = "Solver";
  solver.header = {"item", "value"};
  solver.rows.push_back({"method", rapid::method_name(sol.method)});
  solver.rows.push_back({"objective 1/2 ||y - Phi theta||^2", num(sol.objective, 10)});
  if (sol.method == rapid::Method::Exact) {
    solver.rows.push_back({"certified lower bound", num(sol.lower_bound, 10)});
    solver.rows.push_back({"certified (gap within tolerance)", sol.certified ? "yes" : "no (box limit reached)"});
    solver.rows.push_back({"boxes of the branch and bound", std::to_string(sol.boxes)});
  }
  if (sol.method == rapid::Method::Ga) solver.rows.push_back({"seed", std::to_string(sol.seed)});
  solver.rows.push_back({"Kuhn-Tucker case (thesis Table 3.1)", sol.kkt_case.empty() ? "-" : sol.kkt_case});
  solver.rows.push_back({"within the bounds", sol.feasible ? "yes" : "no"});
  solver.rows.push_back({"search variables", fmt::format("wn {} Hz, zeta {}, p {} Hz", num(sol.wn / kTwoPi),
                                                         num(sol.zeta), num(sol.p / kTwoPi))});
  solver.rows.push_back({"time [ms]", num(sol.time_ms, 4)});
  for (const auto& w : sol.warnings) solver.rows.push_back({"warning", w});
  s.tables.push_back(std::move(solver));

  Table active;
  active.title = "Active bounds";
  active.header = {"bound", "Kuhn-Tucker multiplier"};
  for (const auto& a : sol.active) active.rows.push_back({a.name, num(a.multiplier)});
  if (sol.active.empty()) active.rows.push_back({"none (the optimum is inside the bounds)", "-"});
  s.tables.push_back(std::move(active));

  if (id.fit || id.validation) {
    Table fit;
    fit.title = "Simulated tracking error against the measured one (all samples of each set pooled)";
    fit.header = fit_header("data", u);
    if (id.fit) fit.rows.push_back(fit_row("identification", *id.fit));
    if (id.validation) fit.rows.push_back(fit_row("validation", *id.validation));
    s.tables.push_back(std::move(fit));
  }

  if (!id.shift_trials.empty()) {
    Table trials;
    trials.title = "Command shift search (NRMSE of the simulated tracking error on the identification data; "
                   "\"> x\": simulation stopped once the shift could no longer be chosen)";
    trials.header = {"shift [samples]", "NRMSE", "stable", "chosen"};
    for (const auto& t : id.shift_trials)
      trials.rows.push_back({std::to_string(t.shift), (t.complete ? "" : "> ") + num(t.nrmse, 5), t.stable ? "yes" : "no",
                             t.shift == id.regressors.command_shift ? "yes" : ""});
    s.tables.push_back(std::move(trials));
  }
  return s;
}

// ---- frequency responses --------------------------------------------------------------------

std::string root_text(std::complex<double> r) {
  if (r.imag() == 0.0) return num(r.real());
  return num(r.real()) + " \u00B1 j" + num(std::abs(r.imag()));
}

void add_roots(Table& table, const char* kind, const std::vector<core::ModalInfo>& roots) {
  const bool pole = std::string_view(kind) == "pole";
  for (const auto& m : roots) {
    if (m.root.imag() < 0.0) continue;  // one row per conjugate pair
    const bool real = m.root.imag() == 0.0;
    std::string note = real ? "real" : "complex pair";
    if (m.root.real() > 0.0) note += pole ? ", UNSTABLE" : ", right half plane (non-minimum phase)";
    table.rows.push_back({kind, num(m.freq_hz), real ? "-" : num(m.zeta, 4), root_text(m.root), note});
  }
}

/// State of one searched variable at the solution: "lower bound active (multiplier ...)" etc.
std::string bound_state(const std::vector<rapid::ActiveBound>& active, const std::string& variable) {
  for (const auto& a : active) {
    if (a.name == variable + "_min") return "at the lower bound (multiplier " + num(a.multiplier, 4) + ")";
    if (a.name == variable + "_max") return "at the upper bound (multiplier " + num(a.multiplier, 4) + ")";
  }
  return "inside";
}

Section frequency_section(const vcnc::AxisIdentification& id, const rapid::AxisModel& model) {
  Section s;
  s.title = "Axis " + id.axis + ": frequency responses";
  const int shift = id.regressors.command_shift;
  s.text = fmt::format(
      "Tracking response x/x_r = (b0 s^3 + b1 s^2 + b2 s + a3)/(s^3 + a1 s^2 + a2 s + a3){} and disturbance "
      "response x/d = -s/(s^3 + a1 s^2 + a2 s + a3), d in acceleration units like the friction d0, d1, up to the "
      "Nyquist frequency {} Hz.",
      shift == 0 ? "" : fmt::format(" times exp(j omega {} Ts) (the command shift of {} samples)", shift, shift),
      num(0.5 / id.ts));

  const auto poles = model.poles();
  const auto zeros = model.zeros();
  Table roots;
  roots.title = "Poles and zeros of the tracking response";
  roots.header = {"", "frequency [Hz]", "damping zeta", "root [rad/s]", ""};
  add_roots(roots, "pole", poles);
  add_roots(roots, "zero", zeros);
  s.tables.push_back(std::move(roots));

  const rapid::Solution& sol = id.solution;
  const rapid::Bounds& b = id.bounds;
  // The model in use: the refined one when refined (its own active bounds), else the solver's.
  const auto& refined = id.refinement;
  const double p = refined ? refined->p : sol.p, wn = refined ? refined->wn : sol.wn;
  const double zeta = refined ? refined->zeta : sol.zeta;
  const std::vector<rapid::ActiveBound>& active = refined ? refined->active : sol.active;
  Table bounds;
  bounds.title = "Bounds of the search: (s + p)(s^2 + 2 zeta wn s + wn^2)";
  bounds.header = {"variable", "lower", "upper", refined ? "refined" : "identified", "state"};
  bounds.rows.push_back({"p [Hz]", num(b.p_min / kTwoPi), num(b.p_max / kTwoPi), num(p / kTwoPi), bound_state(active, "p")});
  bounds.rows.push_back(
      {"wn [Hz]", num(b.wn_min / kTwoPi), num(b.wn_max / kTwoPi), num(wn / kTwoPi), bound_state(active, "wn")});
  bounds.rows.push_back({"zeta", num(b.zeta_min), num(b.zeta_max), num(zeta), bound_state(active, "zeta")});
  s.tables.push_back(std::move(bounds));

  // From a fifth of the lowest pole or zero (at most 0.1 Hz, at least two decades) to Nyquist.
  const double nyquist_hz = 0.5 / id.ts;
  double lowest_hz = std::numeric_limits<double>::infinity();
  for (const auto* roots_of : {&poles, &zeros})
    for (const auto& m : *roots_of)
      if (std::isfinite(m.freq_hz) && m.freq_hz > 0.0) lowest_hz = std::min(lowest_hz, m.freq_hz);
  const double f_lo = std::clamp(std::min(0.1, lowest_hz / 5.0), nyquist_hz * 1e-7, nyquist_hz * 1e-2);
  const std::vector<double> f = core::log_space(f_lo, nyquist_hz, kFrequencyPoints);
  std::vector<double> w(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) w[i] = kTwoPi * f[i];
  auto tracking = model.tracking_response(w);
  for (std::size_t i = 0; i < w.size(); ++i) tracking[i] *= std::polar(1.0, w[i] * shift * id.ts);
  const auto disturbance = model.disturbance_response(w);

  const auto bode = [&](const std::string& title, const std::string& y_label, std::vector<double> y) {
    Chart chart;
    chart.title = title;
    chart.x_label = "frequency [Hz]";
    chart.y_label = y_label;
    chart.x_scale = Scale::Log;
    chart.series.push_back({"axis " + id.axis, f, std::move(y)});
    return chart;
  };
  s.charts.push_back(bode("Tracking response x/x_r: magnitude", "magnitude [dB]", magnitude_db(tracking)));
  s.charts.push_back(bode("Tracking response x/x_r: phase", "phase [deg]", unwrapped_phase_deg(tracking)));
  s.charts.push_back(bode("Disturbance response x/d: magnitude", "magnitude [dB re 1 s^2]", magnitude_db(disturbance)));
  s.charts.push_back(bode("Disturbance response x/d: phase", "phase [deg]", unwrapped_phase_deg(disturbance)));
  return s;
}

// ---- measured vs simulated -----------------------------------------------------------------

Section simulation_section(const vcnc::AxisIdentification& id, const rapid::AxisModel& model,
                           const std::vector<UsedCapture>& used) {
  Section s;
  s.title = "Axis " + id.axis + ": measured vs simulated tracking error";
  s.text = fmt::format(
      "Tracking error x_r - x as measured and as the model predicts it: the model is simulated on each capture's "
      "command{}, starting at the capture's first actual position. The simulation sees only the command, never "
      "the measured position, so this is the error the model would predict for a new program.",
      id.regressors.command_shift == 0 ? ""
                                       : fmt::format(" shifted by {} samples", id.regressors.command_shift));
  Table table;
  table.title = "Per capture";
  table.header = fit_header("capture", id.length_unit);
  table.header.insert(table.header.begin() + 1, "use");

  rapid::ModelSimulationOptions options;
  options.command_shift = id.regressors.command_shift;
  for (const auto& u : used) {
    const core::AxisTrace& trace = require_axis(*u.capture, id.axis);
    const std::string& name = u.capture->source;
    std::vector<double> measured(trace.cmd.size());
    for (std::size_t k = 0; k < measured.size(); ++k) measured[k] = trace.cmd[k] - trace.act[k];
    if (measured.empty()) {
      table.rows.push_back({name, u.use, "0"});
      continue;
    }
    options.initial_position = trace.act.front();
    rapid::ModelResponse response;
    try {
      response = model.simulate(trace.cmd, options);
    } catch (const core::InputError& e) {
      table.rows.push_back({name, u.use, std::to_string(measured.size()), "simulation failed: " + e.reason()});
      continue;
    }
    std::vector<double> difference(measured.size());
    for (std::size_t k = 0; k < measured.size(); ++k) difference[k] = measured[k] - response.tracking_error[k];
    try {
      std::vector<std::string> row = fit_row(name, rapid::compare_tracking(measured, response.tracking_error));
      row.insert(row.begin() + 1, u.use);
      table.rows.push_back(std::move(row));
    } catch (const core::InputError&) {
      table.rows.push_back({name, u.use, std::to_string(measured.size()), "-",
                            "the simulation diverges (not finite): the model is unstable"});
    }
    Chart chart;
    chart.title = name + " (" + u.use + "): tracking error x_r - x of axis " + id.axis;
    chart.x_label = "time [s]";
    chart.y_label = "tracking error " + unit_suffix(id.length_unit);
    const std::vector<double> t = capture_time(u.capture->capture);
    chart.series.push_back({"measured", t, std::move(measured)});
    chart.series.push_back({"simulated", t, std::move(response.tracking_error)});
    chart.series.push_back({"measured - simulated", t, std::move(difference)});
    s.charts.push_back(std::move(chart));
  }
  s.tables.insert(s.tables.begin(), std::move(table));
  return s;
}

}  // namespace

Document identification_report(std::span<const vcnc::AxisIdentification> axes,
                               const std::vector<vcnc::NamedCapture>& captures,
                               const std::vector<vcnc::NamedCapture>& validation) {
  if (axes.empty()) throw core::InputError({"", 0, 0, "axes"}, "an identification report needs at least one axis");
  const std::vector<UsedCapture> used = all_captures(captures, validation);
  std::vector<std::string> names, sources, checks;
  for (const auto& a : axes) names.push_back(a.axis);
  for (const auto& c : captures) sources.push_back(c.source);
  for (const auto& c : validation) checks.push_back(c.source);

  Document doc;
  doc.title = (axes.size() == 1 ? "Identification of axis " : "Identification of axes ") + joined(names);
  doc.subtitle = "From " + (sources.empty() ? std::string("no capture") : joined(sources));
  if (!checks.empty()) doc.subtitle += "; validated on " + joined(checks);
  doc.subtitle += "; length unit: " + axes.front().length_unit;

  doc.sections.push_back(captures_section(axes, used, axes.front().length_unit));
  for (const auto& id : axes) {
    const rapid::AxisModel model(id.coefficients(), id.ts);
    doc.sections.push_back(model_section(id, model));
    doc.sections.push_back(frequency_section(id, model));
    doc.sections.push_back(simulation_section(id, model, used));
  }
  return doc;
}

Document identification_report(const vcnc::AxisIdentification& axis, const std::vector<vcnc::NamedCapture>& captures,
                               const std::vector<vcnc::NamedCapture>& validation) {
  return identification_report(std::span<const vcnc::AxisIdentification>(&axis, 1), captures, validation);
}

}  // namespace servotwin::report
