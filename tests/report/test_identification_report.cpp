// The identification report of a real identification (fadal-pid virtual machine, thesis Table
// 3.2-style program): sections, tables, and chart data checked against the model's transfer
// functions evaluated here from thesis Eq. 3.3 and against vcnc's own fit metrics.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <string>

#include "report_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/report/identification_report.hpp"

namespace servotwin::report {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace identification_report_test {

using testing::chart_data;
using testing::render;
using testing::thesis_capture;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

struct Fixture {
  std::vector<vcnc::NamedCapture> captures, validation;
  vcnc::AxisIdentification id;
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture out;
    out.captures = {thesis_capture("fadal-pid", 7)};
    out.validation = {thesis_capture("fadal-pid", 11, 80)};
    vcnc::IdentificationSettings settings;
    settings.shift_search = vcnc::ShiftSearch{};
    out.id = vcnc::identify_axis(out.captures, out.validation, "x", settings);
    return out;
  }();
  return f;
}

const Section& section(const Document& doc, const std::string& title) {
  for (const auto& s : doc.sections)
    if (s.title == title) return s;
  throw std::runtime_error("no section '" + title + "'");
}

const Table& table(const Section& s, const std::string& title_start) {
  for (const auto& t : s.tables)
    if (t.title.rfind(title_start, 0) == 0) return t;
  throw std::runtime_error("no table '" + title_start + "' in section '" + s.title + "'");
}

const Series& series(const Chart& c, const std::string& label) {
  for (const auto& s : c.series)
    if (s.label == label) return s;
  throw std::runtime_error("no series '" + label + "' in chart '" + c.title + "'");
}

/// Thesis Eq. 3.3's tracking and disturbance responses at s = j omega, written out here.
std::complex<double> tracking_eq33(const rapid::ModelCoefficients& c, double omega) {
  const std::complex<double> s(0.0, omega);
  return (c.b0 * s * s * s + c.b1 * s * s + c.b2 * s + c.a3) / (s * s * s + c.a1 * s * s + c.a2 * s + c.a3);
}
std::complex<double> disturbance_eq33(const rapid::ModelCoefficients& c, double omega) {
  const std::complex<double> s(0.0, omega);
  return -s / (s * s * s + c.a1 * s * s + c.a2 * s + c.a3);
}

double nrmse(const std::vector<double>& measured, const std::vector<double>& predicted) {
  double mean = 0.0;
  for (double v : measured) mean += v;
  mean /= static_cast<double>(measured.size());
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < measured.size(); ++k) {
    num += (measured[k] - predicted[k]) * (measured[k] - predicted[k]);
    den += (measured[k] - mean) * (measured[k] - mean);
  }
  return std::sqrt(num / den);
}

TEST(IdentificationReport, HasEverySectionTableAndChart) {
  const Fixture& f = fixture();
  const Document doc = identification_report(f.id, f.captures, f.validation);
  EXPECT_EQ(doc.title, "Identification of axis x");
  EXPECT_NE(doc.subtitle.find("fadal-pid seed 7"), std::string::npos);
  EXPECT_NE(doc.subtitle.find("validated on fadal-pid seed 11"), std::string::npos);
  ASSERT_EQ(doc.sections.size(), 4u);
  EXPECT_EQ(doc.sections[0].title, "Captures");
  EXPECT_EQ(doc.sections[1].title, "Axis x: model");
  EXPECT_EQ(doc.sections[2].title, "Axis x: frequency responses");
  EXPECT_EQ(doc.sections[3].title, "Axis x: measured vs simulated tracking error");
  EXPECT_EQ(doc.sections[0].charts.size(), 2u);  // one per capture
  EXPECT_EQ(doc.sections[2].charts.size(), 4u);  // Bode: tracking and disturbance, magnitude and phase
  EXPECT_EQ(doc.sections[3].charts.size(), 2u);  // one per capture
  EXPECT_EQ(chart_count(doc), 8u);

  const Table& captures = table(doc.sections[0], "Captures");
  ASSERT_EQ(captures.rows.size(), 2u);
  EXPECT_EQ(captures.rows[0][1], "identification");
  EXPECT_EQ(captures.rows[1][1], "validation");
  EXPECT_EQ(captures.rows[0][2], std::to_string(f.captures[0].capture.size()));
  EXPECT_EQ(captures.rows[0][4], "1");  // Ts [ms]

  const Section& model = doc.sections[1];
  const Table& coefficients = table(model, "Coefficients");
  ASSERT_EQ(coefficients.rows.size(), 8u);
  EXPECT_EQ(coefficients.rows[1][0], "a2");
  EXPECT_NEAR(std::stod(coefficients.rows[1][1]), f.id.solution.coefficients.a2,
              1e-7 * std::abs(f.id.solution.coefficients.a2));
  EXPECT_EQ(table(model, "Solver").rows[0][1], "exact");
  EXPECT_EQ(table(model, "Active bounds").rows.size(), std::max<std::size_t>(f.id.solution.active.size(), 1));
  const Table& fit = table(model, "Simulated tracking error");
  ASSERT_EQ(fit.rows.size(), 2u);
  EXPECT_EQ(fit.rows[0][0], "identification");
  EXPECT_NEAR(std::stod(fit.rows[0][6]), f.id.fit->nrmse, 1e-3 * f.id.fit->nrmse + 1e-4);
  const Table& shifts = table(model, "Command shift search");
  EXPECT_EQ(shifts.rows.size(), f.id.shift_trials.size());
  std::size_t chosen = 0;
  for (const auto& row : shifts.rows) chosen += row[3] == "yes" ? 1 : 0;
  EXPECT_EQ(chosen, 1u);

  const Section& frequency = doc.sections[2];
  const rapid::AxisModel m(f.id.solution.coefficients, f.id.ts);
  std::size_t upper_half = 0;
  for (const auto& p : m.poles()) upper_half += p.root.imag() >= 0.0 ? 1 : 0;
  for (const auto& z : m.zeros()) upper_half += z.root.imag() >= 0.0 ? 1 : 0;
  EXPECT_EQ(table(frequency, "Poles and zeros").rows.size(), upper_half);
  const Table& bounds = table(frequency, "Bounds");
  ASSERT_EQ(bounds.rows.size(), 3u);
  EXPECT_EQ(bounds.rows[2][0], "zeta");
  EXPECT_NEAR(std::stod(bounds.rows[2][1]), f.id.bounds.zeta_min, 1e-12);
}

TEST(IdentificationReport, BodePlotsMatchEquation33) {
  const Fixture& f = fixture();
  const Document doc = identification_report(f.id, f.captures, f.validation);
  const Section& s = section(doc, "Axis x: frequency responses");
  const rapid::ModelCoefficients& c = f.id.solution.coefficients;
  const int shift = f.id.regressors.command_shift;
  const Series& mag = s.charts[0].series.front();
  const Series& phase = s.charts[1].series.front();
  const Series& dmag = s.charts[2].series.front();
  const Series& dphase = s.charts[3].series.front();
  EXPECT_EQ(s.charts[0].x_scale, Scale::Log);
  ASSERT_GE(mag.x.size(), 100u);
  EXPECT_LE(mag.x.front(), 0.1);
  EXPECT_NEAR(mag.x.back(), 0.5 / f.id.ts, 1e-9);  // Nyquist
  for (std::size_t i = 0; i < mag.x.size(); ++i) {
    const double w = kTwoPi * mag.x[i];
    const std::complex<double> g = tracking_eq33(c, w) * std::polar(1.0, w * shift * f.id.ts);
    const std::complex<double> d = disturbance_eq33(c, w);
    EXPECT_NEAR(mag.y[i], 20.0 * std::log10(std::abs(g)), 1e-9);
    EXPECT_NEAR(dmag.y[i], 20.0 * std::log10(std::abs(d)), 1e-9);
    // The unwrapped phase equals the principal one modulo 360 and moves continuously.
    const double wrapped = std::remainder(phase.y[i] - std::arg(g) * 180.0 / std::numbers::pi, 360.0);
    EXPECT_NEAR(wrapped, 0.0, 1e-7);
    EXPECT_NEAR(std::remainder(dphase.y[i] - std::arg(d) * 180.0 / std::numbers::pi, 360.0), 0.0, 1e-7);
    if (i > 0) {
      EXPECT_LT(std::abs(phase.y[i] - phase.y[i - 1]), 90.0);
      EXPECT_LT(std::abs(dphase.y[i] - dphase.y[i - 1]), 90.0);
    }
  }
  // The integrator (a3 != 0) tracks without static error: 0 dB at low frequency.
  EXPECT_NEAR(mag.y.front(), 0.0, 0.05);
}

TEST(IdentificationReport, SimulatedErrorIsVcncsSimulatedFit) {
  // vcnc::identify_axis scores the model with its own simulation (vcnc::simulated_fit); the
  // report simulates again for its charts. Both must give the same error sample for sample, so
  // the NRMSE recomputed here from the chart's series equals vcnc's.
  const Fixture& f = fixture();
  const Document doc = identification_report(f.id, f.captures, f.validation);
  const Section& s = section(doc, "Axis x: measured vs simulated tracking error");
  ASSERT_EQ(s.charts.size(), 2u);
  const core::AxisTrace& trace = *f.captures[0].capture.find("x");
  const Series& measured = series(s.charts[0], "measured");
  const Series& simulated = series(s.charts[0], "simulated");
  const Series& difference = series(s.charts[0], "measured - simulated");
  ASSERT_EQ(measured.y.size(), trace.cmd.size());
  for (std::size_t k = 0; k < trace.cmd.size(); k += 97) {
    EXPECT_EQ(measured.y[k], trace.cmd[k] - trace.act[k]);
    EXPECT_EQ(difference.y[k], measured.y[k] - simulated.y[k]);
    EXPECT_DOUBLE_EQ(measured.x[k], f.captures[0].capture.time(k));
  }
  EXPECT_NEAR(nrmse(measured.y, simulated.y), f.id.fit->nrmse, 1e-9 * f.id.fit->nrmse);
  EXPECT_NEAR(nrmse(series(s.charts[1], "measured").y, series(s.charts[1], "simulated").y), f.id.validation->nrmse,
              1e-9 * f.id.validation->nrmse);
  const Table& per_capture = table(s, "Per capture");
  ASSERT_EQ(per_capture.rows.size(), 2u);
  EXPECT_EQ(per_capture.rows[1][1], "validation");
}

TEST(IdentificationReport, RendersAsHtmlWithEveryChart) {
  const Fixture& f = fixture();
  const Document doc = identification_report(f.id, f.captures, f.validation);
  const std::string html = render(doc);
  const nlohmann::json data = chart_data(html);
  ASSERT_EQ(data["charts"].size(), chart_count(doc));
  for (const auto& chart : data["charts"]) {
    ASSERT_FALSE(chart["series"].empty());
    for (const auto& one : chart["series"]) {
      EXPECT_EQ(one["x"].size(), one["y"].size());
      EXPECT_LE(one["x"].size(), HtmlOptions{}.max_points);
    }
  }
  EXPECT_NE(html.find("<h2>Axis x: frequency responses</h2>"), std::string::npos);
}

TEST(IdentificationReport, SeveralAxesShareTheCaptureSection) {
  const machine::MachineConfig machine = machine::preset("fadal-pid");
  motion::IdentificationOptions o = motion::identification_defaults(motion::IdentificationSet::Standard);
  o.axes = {motion::Axis::X, motion::Axis::Y};
  o.moves = 60;
  o.seed = 5;
  const std::vector<vcnc::NamedCapture> captures = {
      {"xy", vcnc::run_program(machine, motion::make_identification_program(o))}};
  std::vector<vcnc::AxisIdentification> axes;
  for (const char* axis : {"x", "y"}) axes.push_back(vcnc::identify_axis(captures, {}, axis, {}));
  const Document doc = identification_report(axes, captures, {});
  EXPECT_EQ(doc.title, "Identification of axes x, y");
  ASSERT_EQ(doc.sections.size(), 7u);
  EXPECT_EQ(doc.sections[4].title, "Axis y: model");
  ASSERT_EQ(doc.sections[0].charts.size(), 1u);
  EXPECT_EQ(doc.sections[0].charts[0].series.size(), 4u);  // x and y: command and actual
  EXPECT_EQ(doc.sections[0].tables[0].header.size(), 9u);
  EXPECT_EQ(chart_count(doc), 1u + 2u * 5u);
}

TEST(IdentificationReport, RefinedModelIsTheOneShownWithTheSolversBeside) {
  const Fixture& f = fixture();
  vcnc::AxisIdentification refined = f.id;
  vcnc::refine_identification(refined, f.captures);
  ASSERT_TRUE(refined.refinement.has_value());
  const Document doc = identification_report(refined, f.captures, f.validation);
  const Section& model = doc.sections[1];
  EXPECT_NE(model.text.find("refined by output error"), std::string::npos);
  const Table& coefficients = table(model, "Coefficients");
  EXPECT_NEAR(std::stod(coefficients.rows[1][1]), refined.coefficients().a2, 1e-7 * std::abs(refined.coefficients().a2));
  EXPECT_NE(refined.coefficients().a2, refined.solution.coefficients.a2);
  const Table& bounds = table(section(doc, "Axis x: frequency responses"), "Bounds");
  EXPECT_EQ(bounds.header[3], "refined");
  EXPECT_NEAR(std::stod(bounds.rows[1][3]), refined.refinement->wn / kTwoPi, 1e-4 * refined.refinement->wn / kTwoPi);
  EXPECT_EQ(table(model, "Solver").rows[0][1], "exact");  // the solver's own table stays the solver's
}

TEST(IdentificationReport, UnstableModelIsReportedNotRefused) {
  Fixture f = fixture();
  f.id.solution.coefficients.a1 = -200.0;  // a pole far in the right half plane
  const Document doc = identification_report(f.id, f.captures, {});
  const Section& model = section(doc, "Axis x: model");
  EXPECT_NE(model.text.find("UNSTABLE"), std::string::npos);
  const Section& s = section(doc, "Axis x: measured vs simulated tracking error");
  const Table& per_capture = table(s, "Per capture");
  ASSERT_EQ(per_capture.rows.size(), 1u);
  const std::string row_text = per_capture.rows[0].back();
  EXPECT_TRUE(row_text.find("unstable") != std::string::npos || row_text.find("simulation failed") != std::string::npos)
      << row_text;
  const nlohmann::json data = chart_data(render(doc));  // non-finite values are written as null
  EXPECT_EQ(data["charts"].size(), chart_count(doc));
}

TEST(IdentificationReport, MissingAxisNamesTheCapture) {
  const Fixture& f = fixture();
  vcnc::AxisIdentification z = f.id;
  z.axis = "z";
  try {
    identification_report(z, f.captures, {});
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().file, "fadal-pid seed 7");
    EXPECT_NE(std::string(e.what()).find("'z'"), std::string::npos);
  }
  EXPECT_THROW(identification_report(std::span<const vcnc::AxisIdentification>{}, f.captures, {}), core::InputError);
}

}  // namespace identification_report_test
}  // namespace
}  // namespace servotwin::report
