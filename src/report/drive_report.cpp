#include "servotwin/report/drive_report.hpp"

#include <fmt/core.h>

#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include "number_format.hpp"

namespace servotwin::report {

namespace {

using Signal = std::function<double(const vcnc::DriveSample&)>;

std::string num(double v, int digits = 4) { return detail::format_number(v, digits); }

std::string time_or_never(double t) { return std::isfinite(t) ? num(t) : "never"; }

bool position_loop(const vcnc::DriveSimulation& s) { return tuning::controls_position(s.structure); }

/// What is controlled, in words, and how to read it from a sample.
std::string controlled_name(const vcnc::DriveSimulation& s) {
  return std::string(s.load_side ? "load " : "motor ") + (position_loop(s) ? "position" : "velocity");
}
std::string unit_of(const vcnc::DriveSimulation& s) { return position_loop(s) ? "rad" : "rad/s"; }

std::vector<double> column(const std::vector<vcnc::DriveSample>& samples, const Signal& f) {
  std::vector<double> v;
  v.reserve(samples.size());
  for (const auto& x : samples) v.push_back(f(x));
  return v;
}

Chart time_chart(std::string title, std::string y_label) {
  Chart c;
  c.title = std::move(title);
  c.x_label = "time [s]";
  c.y_label = std::move(y_label);
  return c;
}

/// One chart of a signal for the plant and its linear part (and optional extra series).
Chart pair_chart(const vcnc::DriveSimulation& s, const std::string& title, const std::string& y_label, const Signal& f) {
  Chart c = time_chart(title, y_label);
  const auto t = column(s.samples, [](const vcnc::DriveSample& x) { return x.t; });
  c.series.push_back({"plant (nonlinear)", t, column(s.samples, f)});
  c.series.push_back({"linear part", t, column(s.linear_samples, f)});
  return c;
}

std::vector<Chart> charts(const vcnc::DriveSimulation& s) {
  const auto t = column(s.samples, [](const vcnc::DriveSample& x) { return x.t; });
  std::vector<Chart> out;
  const std::string what = controlled_name(s);
  Chart controlled = pair_chart(s, fmt::format("{} ({})", what, vcnc::to_string(s.test)),
                                fmt::format("{} [{}]", what, unit_of(s)), vcnc::controlled_variable(s));
  if (s.test == vcnc::DriveTest::kSetpointStep)
    controlled.series.push_back({"reference", t, column(s.samples, [](const vcnc::DriveSample& x) { return x.reference; })});
  out.push_back(std::move(controlled));
  if (s.load_side || position_loop(s))
    out.push_back(pair_chart(s, "Motor velocity", "motor velocity [rad/s]",
                             [](const vcnc::DriveSample& x) { return x.motor_velocity; }));
  Chart torque = pair_chart(s, "Torque command", "torque [N m]", [](const vcnc::DriveSample& x) { return x.torque_command; });
  if (s.torque_limit) {
    torque.series.push_back({"limit", {t.front(), t.back()}, {*s.torque_limit, *s.torque_limit}});
    torque.series.push_back({"-limit", {t.front(), t.back()}, {-*s.torque_limit, -*s.torque_limit}});
  }
  out.push_back(std::move(torque));
  Chart measured = time_chart("Measured output (noise, quantization)", "measured [plant units]");
  measured.series.push_back({"measured", t, column(s.samples, [](const vcnc::DriveSample& x) { return x.measured; })});
  out.push_back(std::move(measured));
  return out;
}

Table metrics_table(const vcnc::DriveSimulation& s) {
  Table t;
  t.title = "Metrics";
  t.header = {"quantity", "plant (nonlinear)", "linear part"};
  const auto& a = s.metrics;
  const auto& b = s.linear_metrics;
  const auto row = [&t](std::string name, std::string x, std::string y) {
    t.rows.push_back({std::move(name), std::move(x), std::move(y)});
  };
  if (s.test == vcnc::DriveTest::kSetpointStep) {
    row("rise time 10–90 % [s]", time_or_never(a.rise_time), time_or_never(b.rise_time));
    row("overshoot [%]", num(100.0 * a.overshoot), num(100.0 * b.overshoot));
    row("motor overshoot [%]", num(100.0 * a.overshoot_motor), num(100.0 * b.overshoot_motor));
    row(fmt::format("settling time ({:g} % band) [s]", 100.0 * s.settling_band), time_or_never(a.settling_time),
        time_or_never(b.settling_time));
  } else {
    row("peak deviation", num(a.peak_deviation), num(b.peak_deviation));
    row("peak motor deviation", num(a.peak_deviation_motor), num(b.peak_deviation_motor));
    row(fmt::format("recovery time ({:g} % of the peak) [s]", 100.0 * s.settling_band), time_or_never(a.recovery_time),
        time_or_never(b.recovery_time));
  }
  row("ITAE", num(a.itae), num(b.itae));
  row("final error (mean of the last 10 %)", num(a.final_error), num(b.final_error));
  row("residual peak-to-peak (last 10 %)", num(a.residual_oscillation), num(b.residual_oscillation));
  row("peak torque [N m]", num(a.peak_torque), num(b.peak_torque));
  row("torque limit active [% of samples]", num(100.0 * a.saturated_fraction), "-");
  return t;
}

Table gains_table(const vcnc::DriveSimulation& s) {
  Table t;
  t.title = "Controller and run";
  t.header = {"quantity", "value"};
  t.rows.push_back({"structure", tuning::to_string(s.structure)});
  if (s.full_order) {
    const tuning::FullOrderSummary& f = *s.full_order;
    t.rows.push_back({"compensator states", std::to_string(f.compensator.states())});
    if (f.hinf) {
      t.rows.push_back({"ω0S/ωz, ω0T/ωz", num(f.hinf->omega_0s, 4) + ", " + num(f.hinf->omega_0t, 4)});
      t.rows.push_back({"γ", num(f.hinf->gamma, 4)});
    } else {
      t.rows.push_back({"kbw", num(f.weights.kbw, 4)});
      t.rows.push_back({"feedforward kff (normalized)", num(f.weights.feedforward, 4)});
    }
    t.rows.push_back({"compensator", f.controller_stable ? "stable" : "UNSTABLE (stable only in closed loop)"});
  } else {
    t.rows.push_back({"Kp", num(s.gains.kp, 6)});
    t.rows.push_back({"Ki", num(s.gains.ki, 6)});
    if (s.gains.kd != 0.0) {
      t.rows.push_back({"Kd", num(s.gains.kd, 6)});
      t.rows.push_back({"τ [s]", num(s.gains.tau, 4)});
    }
    t.rows.push_back({"setpoint weight wp", num(s.gains.wp, 4)});
  }
  if (s.kpp) t.rows.push_back({"Kpp [1/s]", num(*s.kpp, 6)});
  t.rows.push_back({"sample period [s]", num(s.ts, 6)});
  t.rows.push_back({"step", fmt::format("{} of {} {}", vcnc::to_string(s.test), num(s.amplitude),
                                        s.test == vcnc::DriveTest::kLoadStep ? "N m" : unit_of(s))});
  t.rows.push_back({"torque limit [N m]", s.torque_limit ? num(*s.torque_limit) : "none"});
  return t;
}

}  // namespace

Section drive_section(const vcnc::DriveSimulation& s, const std::string& title) {
  Section section;
  section.title = title;
  section.text = fmt::format(
      "The controller, discretized at the plant's sample period as a drive runs it, closes the loop around the "
      "plant with its nonlinearities (friction, backlash, quantization, noise, delay{}); the same loop on the "
      "plant's linear part shows what the linear design predicts. Controlled variable: {}.",
      s.torque_limit ? ", torque limit" : "", controlled_name(s));
  for (const std::string& n : s.notes) section.text += "\n\nNote: " + n;
  section.tables.push_back(metrics_table(s));
  section.charts = charts(s);
  return section;
}

Document drive_report(const vcnc::DriveSimulation& s, const DriveReportOptions& options) {
  Document doc;
  doc.title = fmt::format("Closed-loop simulation: {} test", vcnc::to_string(s.test));
  doc.subtitle = fmt::format("controller {} on plant {}", options.controller_source.empty() ? "(given)" : options.controller_source,
                             options.plant_source.empty() ? "(given)" : options.plant_source);
  Section run = drive_section(s, "Responses");
  run.tables.insert(run.tables.begin(), gains_table(s));
  doc.sections.push_back(std::move(run));
  return doc;
}

}  // namespace servotwin::report
