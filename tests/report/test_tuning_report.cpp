// The tuning report: its charts carry the library's loop functions de-normalized to Hz and model
// units, its tables the tuner's numbers, and its step responses settle where the closed loop's
// final values say. Plants: a two-mass velocity model K (s² + 2ζz ωz s + ωz²)/(s (s² + 2 r ζz ωz s
// + r² ωz²)) in physical units (ωz ≠ 1 so that every Hz and model-unit conversion is exercised),
// and the catalog's Table 5.1 plant (0.5 s² + 0.06 s + 0.5)/(s³ + 1.1 s² + 9.18 s + 1.8) (with
// viscous friction, as the `table-5.1` preset). Independent references: the physical W2 evaluated
// at jω [rad/s] (not through tuning::to_normalized_time), the closed forms C(j∞) = wp·Kp for the
// torque step at t = 0 and the final values 1 (integral action: setpoint) and 0 (load torque), and
// the no-overshoot property ‖φl/φ*‖∞ <= 1 of the chosen position gain.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>

#include "report_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/report/tuning_report.hpp"
#include "servotwin/tuning/position_loop.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::report {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace tuning_report_test {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// The tables' number format ({:.Ng} of fmt, i.e. printf's %.*g for finite values).
std::string num(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
  return buffer;
}

fit::PlantModel two_mass_model(double r, double zeta_z, double omega_z, double im) {
  fit::PlantModel m;
  m.rigid = fit::RigidKind::kIntegrator;
  m.gain = 1.0 / im;
  m.modes = {{{omega_z, zeta_z}, {r * omega_z, r * zeta_z}}};
  return m;
}

fit::PlantModel table_5_1_model() {
  return fit::plant_model_from_transfer_function(
      core::TransferFunction(core::Polynomial({0.5, 0.06, 0.5}), core::Polynomial({1.0, 1.1, 9.18, 1.8})));
}

const Section* find_section(const Document& doc, const std::string& title) {
  for (const Section& s : doc.sections)
    if (s.title == title) return &s;
  return nullptr;
}

const Chart* find_chart(const Section& s, const std::string& title) {
  for (const Chart& c : s.charts)
    if (c.title == title) return &c;
  return nullptr;
}

const Series* find_series(const Chart& c, const std::string& label) {
  for (const Series& s : c.series)
    if (s.label == label) return &s;
  return nullptr;
}

const Table* find_table(const Section& s, const std::string& title_prefix) {
  for (const Table& t : s.tables)
    if (t.title.rfind(title_prefix, 0) == 0) return &t;
  return nullptr;
}

/// The object a find_* found; a missing one fails the test (gtest reports the exception).
template <class T>
const T& must(const T* p) {
  if (p == nullptr) throw std::runtime_error("a section, chart, series or table the test needs is missing");
  return *p;
}

/// The value cell of the row whose first cell is `name`.
std::string cell(const Table& t, const std::string& name, std::size_t column = 1) {
  for (const auto& row : t.rows)
    if (!row.empty() && row[0] == name && column < row.size()) return row[column];
  return "<missing>";
}

/// Every series of the document finite, except the scan's gaps for unstable candidates.
void expect_finite(const Document& doc, const tuning::TuneResult& r) {
  bool unstable_candidate = false;
  for (const auto& k : r.scan) unstable_candidate = unstable_candidate || !k.stable;
  for (const Section& s : doc.sections)
    for (const Chart& c : s.charts)
      for (const Series& series : c.series) {
        ASSERT_EQ(series.x.size(), series.y.size()) << c.title << " / " << series.label;
        ASSERT_FALSE(series.x.empty()) << c.title << " / " << series.label;
        const bool scan = c.title.rfind("Automatic", 0) == 0;
        for (std::size_t k = 0; k < series.y.size(); ++k) {
          EXPECT_TRUE(std::isfinite(series.x[k])) << c.title << " / " << series.label << " x[" << k << "]";
          if (scan && (unstable_candidate || series.label == "candidates within the limits")) continue;
          EXPECT_TRUE(std::isfinite(series.y[k])) << c.title << " / " << series.label << " y[" << k << "]";
        }
      }
}

/// write_html carries every chart: one data entry per chart, each with its title.
void expect_html_has_every_chart(const Document& doc, std::size_t max_bytes) {
  const std::string html = testing::render(doc);
  const nlohmann::json data = testing::chart_data(html).at("charts");
  EXPECT_EQ(data.size(), chart_count(doc));
  std::size_t k = 0;
  for (const Section& s : doc.sections)
    for (const Chart& c : s.charts) {
      ASSERT_LT(k, data.size());
      EXPECT_EQ(data[k].at("title").get<std::string>(), c.title);
      EXPECT_EQ(data[k].at("series").size(), c.series.size()) << c.title;
      ++k;
    }
  EXPECT_LT(html.size(), max_bytes);
}

TEST(TuningReport, PiWithAutomaticOmegaStarCarriesTheLoopFunctionsInHz) {
  const double wz = kTwoPi * 53.0, im = 4.8e-3;
  tuning::TuneOptions o;
  o.hf.delay_s = 2e-4;
  const tuning::TuneResult r = tuning::tune(two_mass_model(2.2, 0.02, wz, im), o);
  ASSERT_FALSE(r.scan.empty());
  const Document doc = tuning_report(r, {"bench", std::nullopt});
  EXPECT_NE(doc.subtitle.find("bench"), std::string::npos);

  for (const char* title : {"Plant", "Design", "Loop shapes", "Robustness", "Time responses (linear)"})
    EXPECT_NE(find_section(doc, title), nullptr) << title;
  EXPECT_EQ(find_section(doc, "Position loop"), nullptr);

  // Plant: ωz in Hz, Bode of the design model and of the model with the delay.
  const Section& plant = must(find_section(doc, "Plant"));
  const Table* params = find_table(plant, "Normalized plant");
  ASSERT_NE(params, nullptr);
  EXPECT_EQ(cell(*params, "antiresonance ωz"), num(53.0, 5));
  EXPECT_EQ(cell(*params, "resonance ratio r"), num(2.2, 5));
  ASSERT_NE(find_table(plant, "Known high-frequency dynamics"), nullptr);
  EXPECT_EQ(cell(must(find_table(plant, "Known high-frequency dynamics")), "delay T"), "0.2");
  const Chart* plant_mag = find_chart(plant, "Plant magnitude |ωm/Tm|");
  ASSERT_NE(plant_mag, nullptr);
  const Series* design = find_series(*plant_mag, "design model (first mode)");
  const Series* with_hf = find_series(*plant_mag, "with the known HF dynamics");
  ASSERT_NE(design, nullptr);
  ASSERT_NE(with_hf, nullptr);
  for (std::size_t k : {std::size_t{0}, design->x.size() / 3, design->x.size() - 1}) {
    // The physical model at 2π f [rad/s]: K (s² + 2ζz ωz s + ωz²)/(s (s² + …)); the delay has |.| = 1.
    const fit::PlantModel m = two_mass_model(2.2, 0.02, wz, im);
    const double expected = 20.0 * std::log10(std::abs(m.response(kTwoPi * design->x[k])));
    EXPECT_NEAR(design->y[k], expected, 1e-9) << k;
    EXPECT_NEAR(with_hf->y[k], expected, 1e-9) << k;
  }

  // Loop shapes: |S| and |ωl/ω*| at sample indices equal the library's functions at ω = 2π f/ωz.
  const Section& shapes = must(find_section(doc, "Loop shapes"));
  const Chart* sensitivity = find_chart(shapes, "Sensitivity and tracking");
  ASSERT_NE(sensitivity, nullptr);
  const Series* s = find_series(*sensitivity, "|S|");
  const Series* tl = find_series(*sensitivity, "|ωl/ω*|");
  ASSERT_NE(s, nullptr);
  ASSERT_NE(tl, nullptr);
  ASSERT_GE(s->x.size(), 400u);
  const tuning::VelocityLoop loop(r.plant, r.controller.normalized);
  for (std::size_t k : {std::size_t{7}, s->x.size() / 2, s->x.size() - 3}) {
    const double w = kTwoPi * s->x[k] / wz;
    EXPECT_NEAR(s->y[k], 20.0 * std::log10(std::abs(loop.sensitivity(w))), 1e-9) << k;
    EXPECT_NEAR(tl->y[k], 20.0 * std::log10(std::abs(loop.load_tracking(w))), 1e-9) << k;
  }
  // The grid contains ωz itself (53 Hz), and the drawn |S| peak does not exceed the analysis' ‖S‖∞.
  EXPECT_NE(std::find_if(s->x.begin(), s->x.end(), [](double f) { return std::abs(f - 53.0) < 1e-9; }), s->x.end());
  EXPECT_LE(*std::max_element(s->y.begin(), s->y.end()), 20.0 * std::log10(r.controller.predicted.peak_s) + 1e-9);
  EXPECT_GE(*std::max_element(s->y.begin(), s->y.end()), 20.0 * std::log10(r.controller.predicted.peak_s) - 0.05);
  // Controller in model units: |C(jω)| = |Kp + Ki/(jω)| with the physical gains at ω = 2π f [rad/s].
  const Series& c = must(find_chart(shapes, "Controller |C(jω)|")).series.front();
  for (std::size_t k : {std::size_t{0}, c.x.size() / 2}) {
    const std::complex<double> jw(0.0, kTwoPi * c.x[k]);
    EXPECT_NEAR(c.y[k], 20.0 * std::log10(std::abs(r.controller.physical.kp + r.controller.physical.ki / jw)), 1e-9);
  }
  const Table* margins = find_table(shapes, "Margins and peaks");
  ASSERT_NE(margins, nullptr);
  EXPECT_EQ(cell(*margins, "phase margin"), num(r.controller.predicted.phase_margin_deg, 4));
  EXPECT_EQ(cell(*margins, "gain margin", 2),
            "dB at " + num(r.controller.predicted.phase_crossover * wz / kTwoPi, 5) + " Hz");

  // Design: the scan in Hz and the chosen ω* marked.
  const Section& d = must(find_section(doc, "Design"));
  ASSERT_EQ(d.charts.size(), 2u);
  const Series& bw = d.charts[0].series[0];
  ASSERT_EQ(bw.x.size(), r.scan.size());
  for (std::size_t k = 0; k < r.scan.size(); ++k) {
    EXPECT_NEAR(bw.x[k], r.scan[k].omega_star * wz / kTwoPi, 1e-9 * bw.x[k]);
    if (r.scan[k].stable) {
      EXPECT_NEAR(bw.y[k], r.scan[k].bandwidth * wz / kTwoPi, 1e-9 * (1.0 + bw.y[k]));
    }
  }
  const Series* marker = find_series(d.charts[1], "chosen ω*");
  ASSERT_NE(marker, nullptr);
  ASSERT_EQ(marker->x.size(), 2u);
  EXPECT_NEAR(marker->x[0], r.controller.design.omega_star * wz / kTwoPi, 1e-5 * marker->x[0]);
  EXPECT_LT(marker->x[0], marker->x[1]);
  const Series* ms = find_series(d.charts[1], "Ms");
  ASSERT_NE(ms, nullptr);
  EXPECT_EQ(ms->y.front(), 1.5);
  EXPECT_NE(find_table(d, "Closed-loop poles"), nullptr);
  EXPECT_NE(find_table(d, "Automatic ω* scan"), nullptr);

  // Time responses: the analysis' horizon in seconds; the torque at t = 0 is wp·Kp (R(∞)/(1 + L(∞))
  // with L(∞) = 0); the velocity settles at 1, the load-torque step's velocity at 0 (integral action).
  const Section& time = must(find_section(doc, "Time responses (linear)"));
  const Chart* step = find_chart(time, "Velocity setpoint step");
  ASSERT_NE(step, nullptr);
  const Series& wl = must(find_series(*step, "load velocity ωl"));
  EXPECT_NEAR(wl.x.back(), r.controller.predicted.horizon / wz, 1e-9 * wl.x.back());
  EXPECT_LE(wl.x.size(), 1200u);
  EXPECT_NEAR(wl.y.back(), 1.0, 1e-4);
  EXPECT_NEAR(*std::max_element(wl.y.begin(), wl.y.end()) - 1.0, r.controller.predicted.overshoot, 0.01);
  const Series& u =
      must(find_chart(time, "Torque command for the velocity setpoint step (per unit velocity)")).series.front();
  EXPECT_NEAR(u.y.front(), r.controller.physical.wp * r.controller.physical.kp, 1e-9 * r.controller.physical.kp);
  const Series& dist =
      must(find_series(must(find_chart(time, "Load-torque step (per unit torque)")), "load velocity ωl"));
  const double worst = std::max(std::abs(*std::min_element(dist.y.begin(), dist.y.end())),
                                std::abs(*std::max_element(dist.y.begin(), dist.y.end())));
  EXPECT_GT(worst, 0.0);
  EXPECT_LT(std::abs(dist.y.back()), 1e-4 * worst);
  // Its ITAE by the trapezoid rule on the drawn samples equals the analysis' (normalized, on its own
  // finer grid) de-normalized: ∫ t |ωl| dt [s² × velocity per torque] = ITAE_n/(Im ωz³).
  double itae = 0.0;
  for (std::size_t k = 1; k < dist.x.size(); ++k)
    itae +=
        0.5 * (dist.x[k] - dist.x[k - 1]) * (dist.x[k] * std::abs(dist.y[k]) + dist.x[k - 1] * std::abs(dist.y[k - 1]));
  const double itae_expected = r.controller.predicted.itae_load_step / (im * wz * wz * wz);
  EXPECT_NEAR(itae, itae_expected, 0.01 * itae_expected);

  expect_finite(doc, r);
  expect_html_has_every_chart(doc, 1'000'000);
}

TEST(TuningReport, PidWithW2DrawsTheRobustnessFunctionsOfThePhysicalWeight) {
  const double wz = kTwoPi * 20.0, im = 5e-3;
  tuning::TuneOptions o;
  o.structure = tuning::Structure::kPid;
  o.target_r = 2.0;
  o.ms = o.mt = 1.8;
  // W2(s) = 0.05 (s/ωa + 1)/(s/ωb + 1): 5 % at low frequency, 50 % far above 3 ωz (physical rad/s).
  const double wa = 3.0 * wz, wb = 30.0 * wz;
  o.w2 = core::TransferFunction(core::Polynomial({0.05 / wa, 0.05}), core::Polynomial({1.0 / wb, 1.0}));
  o.hf.current_lag_s = 5e-4;
  const tuning::TuneResult r = tuning::tune(two_mass_model(3.0, 0.02, wz, im), o);
  ASSERT_FALSE(r.scan.empty());
  ASSERT_TRUE(r.controller.robustness.rs.has_value());
  const Document doc = tuning_report(r, {"pid", o.w2});

  const Section& gains = must(find_section(doc, "Design"));
  const Table* g = find_table(gains, "Gains");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(cell(*g, "Kd", 2), num(r.controller.physical.kd, 7));
  EXPECT_EQ(cell(*g, "Kd", 1), num(r.controller.normalized.kd, 7));

  const Section& rob = must(find_section(doc, "Robustness"));
  const Table* t = find_table(rob, "Robust stability");
  ASSERT_NE(t, nullptr);
  // The report re-evaluates the tests with the tuner's settings: the same numbers as the tuner's.
  EXPECT_EQ(cell(*t, "RS: ‖W2 T‖∞"), num(*r.controller.robustness.rs, 5));
  EXPECT_EQ(cell(*t, "NP: ‖S‖∞/Ms"), num(*r.controller.robustness.np, 5));
  EXPECT_EQ(cell(*t, "RP: sup(|S|/Ms + |W2 T|)"), num(*r.controller.robustness.rp, 5));

  ASSERT_EQ(rob.charts.size(), 1u);
  const Series* wt = find_series(rob.charts[0], "|W2 T| (RS)");
  const Series* rp = find_series(rob.charts[0], "|S|/Ms + |W2 T| (RP)");
  ASSERT_NE(wt, nullptr);
  ASSERT_NE(rp, nullptr);
  const tuning::VelocityLoop loop(r.plant, r.controller.normalized);
  for (std::size_t k : {std::size_t{3}, wt->x.size() / 2, wt->x.size() - 2}) {
    const double w_phys = kTwoPi * wt->x[k];
    const std::complex<double> w2 = o.w2->frequency_response(w_phys);  // physical W2 at jω [rad/s]
    const std::complex<double> t_here = loop.complementary(w_phys / wz);
    EXPECT_NEAR(wt->y[k], 20.0 * std::log10(std::abs(w2 * t_here)), 1e-9) << k;
    const double expected_rp = std::abs(loop.sensitivity(w_phys / wz)) / o.ms + std::abs(w2 * t_here);
    EXPECT_NEAR(rp->y[k], 20.0 * std::log10(expected_rp), 1e-9) << k;
  }
  // The grid's maximum of the RP function is the refined supremum from below.
  const double rp_max = *std::max_element(rp->y.begin(), rp->y.end());
  EXPECT_LE(rp_max, 20.0 * std::log10(*r.controller.robustness.rp) + 1e-9);
  EXPECT_GE(rp_max, 20.0 * std::log10(*r.controller.robustness.rp) - 0.05);

  // PID torque at t = 0: C(j∞) with wd = 0 is wp Kp (the derivative acts on the measurement only).
  const Section& time = must(find_section(doc, "Time responses (linear)"));
  const Series& u =
      must(find_chart(time, "Torque command for the velocity setpoint step (per unit velocity)")).series.front();
  EXPECT_NEAR(u.y.front(), r.controller.physical.wp * r.controller.physical.kp, 1e-9 * r.controller.physical.kp);

  expect_finite(doc, r);
  expect_html_has_every_chart(doc, 1'000'000);
}

TEST(TuningReport, PiPlusPShowsThePositionLoopWithoutOvershoot) {
  tuning::TuneOptions o;
  o.structure = tuning::Structure::kPiP;
  o.omega_star = 0.4;
  o.zeta_star = 1.0;
  const tuning::TuneResult r = tuning::tune(table_5_1_model(), o);
  ASSERT_TRUE(r.controller.kpp_normalized.has_value());
  EXPECT_TRUE(r.scan.empty());
  const Document doc = tuning_report(r);
  const Section* position = find_section(doc, "Position loop");
  ASSERT_NE(position, nullptr);
  // Scan charts only for an automatic ω*.
  EXPECT_TRUE(must(find_section(doc, "Design")).charts.empty());
  // Table 5.1: friction realization (Im = 2 per unit gain 0.5, catalog preset values).
  const Table* two_mass = find_table(must(find_section(doc, "Plant")), "Two-mass realization");
  ASSERT_NE(two_mass, nullptr);
  EXPECT_EQ(cell(*two_mass, "motor inertia Im"), "2");
  EXPECT_EQ(cell(*two_mass, "load inertia Il"), num(16.12615039151721, 5));

  const Table* limits = find_table(*position, "Position gain limits");
  ASSERT_NE(limits, nullptr);
  const double wz = r.plant.omega_z;
  EXPECT_EQ(cell(*limits, "chosen"), num(*r.controller.kpp_physical, 5));
  EXPECT_EQ(cell(*limits, "chosen"), num(*r.controller.kpp_normalized * wz, 5));
  EXPECT_EQ(cell(*limits, "robust stability (W2)"), "-");

  const Chart* tracking = find_chart(*position, "Position tracking");
  ASSERT_NE(tracking, nullptr);
  const Series* load = find_series(*tracking, "|φl/φ*|");
  ASSERT_NE(load, nullptr);
  // Kpp is the largest gain without overshoot: the drawn |φl/φ*| stays at or below 0 dB, ~0 dB at
  // the lowest frequency (type-1 loop), and equals the library's function.
  EXPECT_LE(*std::max_element(load->y.begin(), load->y.end()), 1e-6);
  EXPECT_NEAR(load->y.front(), 0.0, 1e-3);
  const tuning::VelocityLoop loop(r.plant, r.controller.normalized);
  const tuning::PositionLoop pl(tuning::functions_of(loop), std::nullopt);
  const std::size_t k = load->x.size() / 2;
  EXPECT_NEAR(load->y[k],
              20.0 * std::log10(std::abs(pl.load_tracking(kTwoPi * load->x[k] / wz, *r.controller.kpp_normalized))),
              1e-9);

  const Chart* step =
      find_chart(must(find_section(doc, "Time responses (linear)")), "Position setpoint step (P position loop)");
  ASSERT_NE(step, nullptr);
  const Series& phi = must(find_series(*step, "load position φl"));
  EXPECT_NEAR(phi.y.back(), 1.0, 1e-4);  // type-1 position loop

  expect_finite(doc, r);
  expect_html_has_every_chart(doc, 1'000'000);
}

TEST(TuningReport, WithoutALoadSideDrawsOnlyTheMotorSide) {
  // Two modes: no two-mass realization, so no load-side functions (they would be NaN).
  fit::PlantModel m = two_mass_model(2.0, 0.03, kTwoPi * 30.0, 1e-2);
  m.modes.push_back({{kTwoPi * 150.0, 0.02}, {kTwoPi * 180.0, 0.02}});
  tuning::TuneOptions o;
  o.omega_star = 0.5;
  const tuning::TuneResult r = tuning::tune(m, o);
  const Document doc = tuning_report(r);
  const Section& plant = must(find_section(doc, "Plant"));
  const Table* modes = find_table(plant, "Higher modes");
  ASSERT_NE(modes, nullptr);
  EXPECT_EQ(cell(*modes, "2", 3), "180");
  EXPECT_NE(find_series(must(find_chart(plant, "Plant magnitude |ωm/Tm|")), "with the higher modes"), nullptr);
  const Section& shapes = must(find_section(doc, "Loop shapes"));
  EXPECT_EQ(find_series(must(find_chart(shapes, "Sensitivity and tracking")), "|ωl/ω*|"), nullptr);
  EXPECT_EQ(find_chart(shapes, "Load-torque disturbance |ωl/Tl|"), nullptr);
  const Section& time = must(find_section(doc, "Time responses (linear)"));
  EXPECT_EQ(find_chart(time, "Load-torque step (per unit torque)"), nullptr);
  EXPECT_EQ(find_series(must(find_chart(time, "Velocity setpoint step")), "load velocity ωl"), nullptr);
  expect_finite(doc, r);
  expect_html_has_every_chart(doc, 1'000'000);
}

TEST(TuningReport, LqgShowsItsDesignAndTheCompensatorsStability) {
  tuning::TuneOptions o;
  o.structure = tuning::Structure::kLqg;
  const tuning::TuneResult r = tuning::tune(table_5_1_model(), o);
  const Document doc = tuning_report(r, {"table-5.1", std::nullopt});
  expect_finite(doc, r);
  expect_html_has_every_chart(doc, 3'000'000);
  EXPECT_NE(doc.subtitle.find("kbw = "), std::string::npos) << doc.subtitle;
  const Section& design = must(find_section(doc, "Design"));
  const Table& lqg = must(find_table(design, "LQG design (C7.13"));
  EXPECT_EQ(cell(lqg, "kbw"), num(r.controller.full_order->weights.kbw, 5));
  EXPECT_EQ(cell(lqg, "compensator states"), "5");
  EXPECT_EQ(cell(lqg, "compensator"), r.controller.full_order->controller_stable ? "stable" : "UNSTABLE");
  EXPECT_NE(find_table(design, "Automatic kbw scan"), nullptr);
  // The step responses are those of the LQG loop: they settle at 1 (integral action).
  const Series& load = must(find_series(must(find_chart(must(find_section(doc, "Time responses (linear)")),
                                                        "Velocity setpoint step")),
                                        "load velocity ωl"));
  EXPECT_NEAR(load.y.back(), 1.0, 1e-3);
}

TEST(ComparisonReport, OneTableAndEveryStructureInEachChart) {
  // table-5.1 (r = 3): PI, PID, LQG and H∞ all design; the table's bandwidths are the designs' own
  // in Hz (× ωz/2π, ωz = 1 rad/s here) and the ratios to the PI; each chart overlays the four.
  const std::vector<tuning::StructureComparison> c = tuning::compare_structures(table_5_1_model(), {});
  const Document doc = comparison_report(c, {"table-5.1"});
  for (const Section& s : doc.sections)
    for (const Chart& chart : s.charts)
      for (const Series& series : chart.series)
        for (double y : series.y) EXPECT_TRUE(std::isfinite(y)) << chart.title << " / " << series.label;
  expect_html_has_every_chart(doc, 3'000'000);
  const Table& t = must(find_table(must(find_section(doc, "Comparison")), "Structures tuned to the same spec"));
  ASSERT_EQ(t.rows.size(), 4U);
  const double hz = 1.0 / kTwoPi;
  for (std::size_t k = 0; k < 4; ++k) {
    const tuning::LoopIndices& i = c[k].result->controller.predicted;
    EXPECT_EQ(t.rows[k][2], num(i.bandwidth_load * hz, 4));
    EXPECT_EQ(t.rows[k][3], "×" + num(i.bandwidth_load / c[0].result->controller.predicted.bandwidth_load, 3));
  }
  const Chart& tracking =
      must(find_chart(must(find_section(doc, "Loop shapes")), "Tracking: load velocity per velocity reference |ωl/ω*|"));
  EXPECT_NE(find_series(tracking, "pi"), nullptr);
  EXPECT_NE(find_series(tracking, "pid"), nullptr);
  EXPECT_NE(find_series(tracking, "lqg"), nullptr);
  EXPECT_NE(find_series(tracking, "hinf"), nullptr);
  const Chart& steps = must(find_chart(must(find_section(doc, "Time responses (linear)")),
                                       "Load velocity after a unit velocity step"));
  for (const Series& series : steps.series) EXPECT_NEAR(series.y.back(), 1.0, 1e-3) << series.label;
  const Chart& load_steps = must(find_chart(must(find_section(doc, "Time responses (linear)")),
                                            "Load velocity after a unit load-torque step"));
  for (const Series& series : load_steps.series) EXPECT_NEAR(series.y.back(), 0.0, 1e-3) << series.label;
}

TEST(ComparisonReport, SimulationsOnThePlantAreOneSectionPerTest) {
  // The compared designs run on a two-mass plant with friction (as in test_drive_report.cpp): a
  // section per test, one table row and one overlaid series per structure, the samples unchanged.
  machine::PlantConfig plant;
  plant.model = machine::two_mass(1.0, 3.0, 3.0, 0.12);
  auto& chain = std::get<machine::MassChain>(plant.model);
  chain.friction = {machine::KarnoppFriction{}, machine::KarnoppFriction{0.02, 0.03, 1e-3}};
  plant.settings.ts = 5e-3;
  const auto tf = machine::mass_chain_transfer_function(chain, machine::PlantOutput::MotorVelocity);
  const std::vector<tuning::StructureComparison> c =
      tuning::compare_structures(fit::plant_model_from_transfer_function(tf), {});
  ComparisonReportOptions o;
  for (const auto& e : c) {
    ASSERT_TRUE(e.result.has_value()) << e.failure;
    vcnc::DriveSimulationSettings s;
    s.duration_s = 20.0;
    o.simulations.push_back(vcnc::simulate_drive(plant, e.result->controller, s));
    s.test = vcnc::DriveTest::kLoadStep;
    s.amplitude = 0.3;
    o.simulations.push_back(vcnc::simulate_drive(plant, e.result->controller, s));
  }
  const Document doc = comparison_report(c, o);
  expect_html_has_every_chart(doc, 5'000'000);
  for (const char* title : {"Simulation on the plant: step", "Simulation on the plant: load-step"}) {
    const Section& s = must(find_section(doc, title));
    ASSERT_EQ(s.tables.size(), 1U);
    EXPECT_EQ(s.tables[0].rows.size(), 4U);
    ASSERT_EQ(s.charts.size(), 2U);
    ASSERT_EQ(s.charts[0].series.size(), 4U);
    EXPECT_EQ(s.charts[0].series[2].label, "lqg");
  }
  const Section& step = must(find_section(doc, "Simulation on the plant: step"));
  const vcnc::DriveSimulation& lqg_step = o.simulations[4];
  EXPECT_EQ(step.charts[0].series[2].y.back(), lqg_step.samples.back().load_velocity);
  EXPECT_EQ(step.tables[0].rows[2][1], num(100.0 * lqg_step.metrics.overshoot, 4));
}

TEST(ComparisonReport, AFailedStructureIsARowWithItsReason) {
  const std::vector<tuning::StructureComparison> c =
      tuning::compare_structures(two_mass_model(1.5, 0.01, kTwoPi * 20.0, 0.01), {});
  const Document doc = comparison_report(c);
  const Table& t = must(find_table(must(find_section(doc, "Comparison")), "Structures tuned to the same spec"));
  ASSERT_EQ(t.rows.size(), 4U);
  EXPECT_EQ(t.rows[1][0], "pid");
  EXPECT_EQ(t.rows[1][1].rfind("not tuned: no omega* meets", 0), 0U) << t.rows[1][1];
  EXPECT_THROW((void)comparison_report({c[1]}), core::InputError);
}

TEST(TuningReport, BadOptionsAreInputErrors) {
  tuning::TuneOptions o;
  o.omega_star = 0.5;
  const tuning::TuneResult r = tuning::tune(two_mass_model(2.0, 0.02, 100.0, 1e-2), o);
  TuningReportOptions bad;
  bad.frequency_points = 3;
  EXPECT_THROW((void)tuning_report(r, bad), core::InputError);
  bad = {};
  bad.time_points = 0;
  EXPECT_THROW((void)tuning_report(r, bad), core::InputError);
  bad = {};
  bad.w2 = core::TransferFunction(core::Polynomial({1.0, 0.0}), core::Polynomial({1.0, -10.0}));  // unstable weight
  try {
    (void)tuning_report(r, bad);
    ADD_FAILURE() << "no InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "w2");
  }
}

}  // namespace tuning_report_test
}  // namespace
}  // namespace servotwin::report
