// Multiplicative uncertainty (catalog C7.9): the W2 envelope fit, RS/NP/RP of a velocity
// loop and the largest ω* passing them. Expected values: closed forms written out here, exactness on
// synthetic residuals of a known W2, brute-force searches in the tests, the catalog's E27 number
// (0.68 printed, 0.681 recomputed) and tests/data/tuning/robust_reference.json written by
// tools/reference/tuning_robust_reference.py (dense-grid scipy evaluation, independent formulation).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "fixture.hpp"
#include "json_fixture.hpp"
#include "servotwin/core/frequency_response.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/uncertainty.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {
namespace {

using core::Polynomial;
using core::TransferFunction;
using test::expect_input_error;
using test::rel_diff;

const nlohmann::json& robust_reference() {
  static const nlohmann::json j =
      test_support::read_json_fixture("tuning/robust_reference.json", "tuning_robust_reference.py");
  return j;
}

Polynomial poly_of(const nlohmann::json& a) { return Polynomial(a.get<std::vector<double>>()); }

/// Residual bounds |w2(jω)| at `n` log-spaced frequencies.
std::vector<ResidualBound> residuals_of(const TransferFunction& w2, double lo, double hi, std::size_t n) {
  std::vector<ResidualBound> out;
  for (double w : core::log_space(lo, hi, n)) out.push_back({w, std::abs(w2.frequency_response(w))});
  return out;
}

/// log-area of an envelope, written out independently of the library: trapezoid in log ω.
double log_area(const TransferFunction& w2, const std::vector<ResidualBound>& pts) {
  double area = 0.0, span = std::log(pts.back().omega / pts.front().omega);
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double a = std::log(std::abs(w2.frequency_response(pts[i].omega)) / pts[i].bound);
    const double b = std::log(std::abs(w2.frequency_response(pts[i + 1].omega)) / pts[i + 1].bound);
    area += 0.5 * (a + b) * std::log(pts[i + 1].omega / pts[i].omega);
  }
  return area / span;
}

void expect_envelope(const UncertaintyEnvelope& e, const std::vector<ResidualBound>& pts) {
  double min_ratio = 1e300;
  for (const ResidualBound& p : pts) {
    const double ratio = std::abs(e.w2.frequency_response(p.omega)) / p.bound;
    EXPECT_GE(ratio, 1.0 - 1e-12) << "envelope below the bound at " << p.omega;
    min_ratio = std::min(min_ratio, ratio);
  }
  // Tight: the binding point sits on the bound (else k could be lowered).
  EXPECT_NEAR(min_ratio, 1.0, 1e-12);
  EXPECT_NEAR(e.min_ratio, min_ratio, 1e-12);
  EXPECT_TRUE(core::is_hurwitz(e.w2.den()));
  for (double c : e.w2.num().coefficients()) EXPECT_GE(c, 0.0);  // zeros in the closed LHP
}

// ------------------------------------------------------------------------- envelope

TEST(UncertaintyEnvelope, RecoversAKnownIntegratingWeightExactly) {
  // The E27 weight 2.6 s/(s + 15): the fit must return it (log-area 0 is the global minimum).
  const TransferFunction truth(Polynomial{2.6, 0.0}, Polynomial{1.0, 15.0});
  const std::vector<ResidualBound> pts = residuals_of(truth, 0.1, 1000.0, 40);
  const UncertaintyEnvelope e = fit_uncertainty_envelope(pts, 1);
  expect_envelope(e, pts);
  EXPECT_LT(e.log_area, 1e-7);
  const TransferFunction w = e.w2.normalized();
  ASSERT_EQ(w.num().degree(), 1);
  EXPECT_NEAR(w.num().coefficient_of_power(1), 2.6, 2.6e-6);
  EXPECT_NEAR(w.num().coefficient_of_power(0), 0.0, 1e-6);
  EXPECT_NEAR(w.den().coefficient_of_power(0), 15.0, 15e-6);
}

TEST(UncertaintyEnvelope, RecoversAKnownBiproperWeightExactly) {
  // 0.3 (s + 2)/(s + 40): |W2| from 0.015 to 0.3.
  const TransferFunction truth(Polynomial{0.3, 0.6}, Polynomial{1.0, 40.0});
  const std::vector<ResidualBound> pts = residuals_of(truth, 0.05, 5000.0, 60);
  const UncertaintyEnvelope e = fit_uncertainty_envelope(pts, 1);
  expect_envelope(e, pts);
  EXPECT_LT(e.log_area, 1e-7);
  const TransferFunction w = e.w2.normalized();
  EXPECT_NEAR(w.num().coefficient_of_power(1), 0.3, 0.3e-5);
  EXPECT_NEAR(w.num().coefficient_of_power(0) / w.num().coefficient_of_power(1), 2.0, 2e-5);
  EXPECT_NEAR(w.den().coefficient_of_power(0), 40.0, 40e-5);
  // Same weight in Hz-scaled frequencies (ω·2π): the corners scale, the gain does not.
  std::vector<ResidualBound> scaled = pts;
  for (ResidualBound& p : scaled) p.omega *= 2.0 * std::numbers::pi;
  const TransferFunction ws = fit_uncertainty_envelope(scaled, 1).w2.normalized();
  EXPECT_NEAR(ws.den().coefficient_of_power(0), 80.0 * std::numbers::pi, 80.0 * std::numbers::pi * 1e-5);
}

TEST(UncertaintyEnvelope, NoisyResidualsStayBelowAndTheAreaBeatsABruteForceGrid) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.15, 1.0);
  const TransferFunction shape(Polynomial{0.8, 0.4}, Polynomial{1.0, 8.0});
  std::vector<ResidualBound> pts = residuals_of(shape, 0.02, 300.0, 80);
  for (ResidualBound& p : pts) p.bound *= u(rng);
  pts[17].bound *= 3.0;  // an outlier the envelope must still cover
  const UncertaintyEnvelope e = fit_uncertainty_envelope(pts, 1);
  expect_envelope(e, pts);
  EXPECT_NEAR(e.log_area, log_area(e.w2, pts), 1e-12);
  // Brute force over the first-order family on a 161 x 161 grid of corners (z = 0 included),
  // k set by the binding point: the fit must be at least as tight (up to the grid's resolution).
  double best = 1e300;
  const std::vector<double> corners = core::log_space(1e-4, 3e4, 161);
  std::vector<double> zeros{0.0};
  zeros.insert(zeros.end(), corners.begin(), corners.end());
  for (double z : zeros) {
    for (double p : corners) {
      const TransferFunction g(Polynomial{1.0, z}, Polynomial{1.0, p});
      double k = 0.0;
      for (const ResidualBound& q : pts) k = std::max(k, q.bound / std::abs(g.frequency_response(q.omega)));
      best = std::min(best, log_area(TransferFunction(k * Polynomial{1.0, z}, Polynomial{1.0, p}), pts));
    }
  }
  EXPECT_LE(e.log_area, best + 1e-9);
}

TEST(UncertaintyEnvelope, SecondOrderIsAnEnvelopeAndNoLooserThanFirstOrder) {
  // A weight with two corners each way: 0.02 (s + 1)(s + 50)/((s + 5)(s + 400)) — not first order.
  const TransferFunction truth(0.02 * (Polynomial{1.0, 1.0} * Polynomial{1.0, 50.0}),
                               Polynomial{1.0, 5.0} * Polynomial{1.0, 400.0});
  const std::vector<ResidualBound> pts = residuals_of(truth, 0.01, 1e4, 80);
  const UncertaintyEnvelope e1 = fit_uncertainty_envelope(pts, 1);
  const UncertaintyEnvelope e2 = fit_uncertainty_envelope(pts, 2);
  expect_envelope(e1, pts);
  expect_envelope(e2, pts);
  EXPECT_EQ(e2.w2.den().degree(), 2);
  EXPECT_GT(e1.log_area, 0.05);                 // a first-order weight cannot follow it
  EXPECT_LT(e2.log_area, 1e-3 * e1.log_area);   // the second-order one nearly reproduces it
}

TEST(UncertaintyEnvelope, ResidualsFromAModelAndMeasuredPoints) {
  // Nominal: integrator, one mode; "measured": the same with other mode data, with a std dev on
  // half of the points. Expected bounds written out from PlantModel::response.
  fit::PlantModel nominal;
  nominal.rigid = fit::RigidKind::kIntegrator;
  nominal.gain = 50.0;
  nominal.modes = {fit::Mode{{30.0, 0.02}, {80.0, 0.03}}};
  fit::PlantModel truth = nominal;
  truth.modes = {fit::Mode{{32.0, 0.03}, {78.0, 0.05}}};
  truth.delay_s = 0.002;
  core::FrequencyResponse measured;
  for (int i = 0; i < 30; ++i) {
    const double f = 0.5 * std::pow(1.2, i);
    core::FrequencyPoint p;
    p.freq_hz = f;
    p.value = truth.response(2.0 * std::numbers::pi * f);
    p.std_dev = (i % 2 == 0) ? 0.01 * std::abs(p.value) : 0.0;
    measured.points.push_back(p);
  }
  const std::vector<ResidualBound> r = relative_residuals(nominal, measured);
  ASSERT_EQ(r.size(), measured.points.size());
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * measured.points[i].freq_hz;
    const std::complex<double> pn = nominal.response(w);
    const double expected = std::abs(measured.points[i].value / pn - 1.0) + 2.0 * measured.points[i].std_dev / std::abs(pn);
    EXPECT_NEAR(r[i].omega, w, 1e-12 * w);
    EXPECT_NEAR(r[i].bound, expected, 1e-12 * expected);
  }
  const UncertaintyEnvelope e = uncertainty_weight_from_residuals(nominal, measured, 1);
  expect_envelope(e, r);
}

TEST(UncertaintyEnvelope, BadInputIsAnInputErrorNamingTheField) {
  fit::PlantModel nominal;
  nominal.modes = {fit::Mode{{30.0, 0.02}, {80.0, 0.03}}};
  core::FrequencyResponse empty;
  expect_input_error([&] { (void)relative_residuals(nominal, empty); }, "measured.points", "at least one");
  core::FrequencyResponse m;
  m.points = {core::FrequencyPoint{10.0, {1.0, 0.0}, 1.0, 0.0, 0.0, 0.0}, core::FrequencyPoint{5.0, {1.0, 0.0}, 1.0, 0.0, 0.0, 0.0}};
  expect_input_error([&] { (void)relative_residuals(nominal, m); }, "measured.points[1].freq_hz", "increasing");
  m.points[1].freq_hz = 20.0;
  m.points[1].std_dev = -1.0;
  expect_input_error([&] { (void)relative_residuals(nominal, m); }, "measured.points[1].std_dev", ">= 0");
  const std::vector<ResidualBound> two{{1.0, 0.1}, {2.0, 0.2}};
  expect_input_error([&] { (void)fit_uncertainty_envelope(two, 1); }, "residuals", "at least 3");
  const std::vector<ResidualBound> bad{{1.0, 0.1}, {-2.0, 0.2}, {3.0, 0.3}};
  expect_input_error([&] { (void)fit_uncertainty_envelope(bad, 1); }, "residuals[1].omega", "> 0");
  const std::vector<ResidualBound> ok{{1.0, 0.1}, {2.0, 0.2}, {3.0, 0.3}};
  expect_input_error([&] { (void)fit_uncertainty_envelope(ok, 3); }, "order", "1 or 2");
}

TEST(UncertaintyEnvelope, NormalizedTimeRescalesTheCorners) {
  // 2.6 s/(s + 150) [rad/s] on a plant with ωz = 10 rad/s is 2.6 s/(s + 15) in normalized time.
  const TransferFunction phys(Polynomial{2.6, 0.0}, Polynomial{1.0, 150.0});
  const TransferFunction n = to_normalized_time(phys, 10.0);
  EXPECT_NEAR(n.num().coefficient_of_power(1), 2.6, 1e-14);
  EXPECT_EQ(n.num().coefficient_of_power(0), 0.0);
  EXPECT_NEAR(n.den().coefficient_of_power(0), 15.0, 1e-13);
  const TransferFunction second(Polynomial{0.1, 3.0, 20.0}, Polynomial{1.0, 30.0, 400.0});
  const TransferFunction n2 = to_normalized_time(second, 7.0);
  for (double w : {0.01, 0.3, 1.0, 4.0, 100.0})
    EXPECT_LT(std::abs(n2.frequency_response(w) - second.frequency_response(7.0 * w)), 1e-14);
  expect_input_error([&] { (void)to_normalized_time(phys, 0.0); }, "omega_z", "> 0");
}

// ------------------------------------------------------------------------- RS / NP / RP

TEST(UncertaintyRobustness, E27NominalLoopMatchesThePrintedValue) {
  // Catalog E27: W2 = 2.6 s/(s + 15), PI (4.63, 0.64) 1-DoF on r = 3, ζz = 0.01: ‖W2 Tvn‖∞ = 0.68
  // printed, 0.681 recomputed. The nominal loop is the delay-free one: W2 is the envelope of the
  // delay D = 0.15 (checked below), it does not act on top of it.
  const nlohmann::json& f = robust_reference().at("e27");
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const VelocityLoop loop(plant, PidGains{4.63, 0.64, 0.0, 0.0, 1.0, 0.0}, false);
  const TransferFunction w2(Polynomial{2.6, 0.0}, Polynomial{1.0, 15.0});
  const RobustnessResult r = robustness(loop, w2, 2.0);
  EXPECT_NEAR(r.rs, 0.681, 2e-3);
  const nlohmann::json& v = f.at("velocity");
  EXPECT_NEAR(r.rs, v.at("rs").get<double>(), 1e-7);
  EXPECT_NEAR(r.np, v.at("np").get<double>(), 1e-7);
  EXPECT_NEAR(r.rp, v.at("rp").get<double>(), 1e-7);
  EXPECT_LT(rel_diff(r.rs_omega, v.at("rs_omega").get<double>()), 1e-3);
  EXPECT_LT(rel_diff(r.np_omega, v.at("np_omega").get<double>()), 1e-3);
  EXPECT_LT(rel_diff(r.rp_omega, v.at("rp_omega").get<double>()), 1e-3);
  EXPECT_TRUE(r.nominally_stable);
  EXPECT_TRUE(r.rs_ok);

  // W2 covers the delay: |e^{−jωD} − 1| <= |W2(jω)| on a dense grid (so P·e^{−sD} = P(1 + ΔW2)) …
  double cover = 0.0;
  for (double w : core::log_space(1e-3, 1e4, 20001))
    cover = std::max(cover, std::abs(std::polar(1.0, -0.15 * w) - 1.0) / std::abs(w2.frequency_response(w)));
  EXPECT_LT(cover, 1.0);
  EXPECT_NEAR(cover, f.at("delay_cover_ratio").get<double>(), 1e-6);
  // … and RS therefore guarantees the delayed loop's stability (Routh with a Padé(6) delay).
  NormalizedPlant delayed = plant;
  delayed.hf.delay_s = 0.15;
  const VelocityLoop with_delay(delayed, PidGains{4.63, 0.64, 0.0, 0.0, 1.0, 0.0}, true);
  EXPECT_TRUE(with_delay.stable());
  // Putting the delay inside the nominal loop as well counts it twice: ‖W2 T‖∞ = 1.79.
  const RobustnessResult twice = robustness(with_delay, w2, 2.0);
  EXPECT_NEAR(twice.rs, f.at("rs_with_delay_inside").get<double>(), 1e-6);
  EXPECT_FALSE(twice.rs_ok);
}

TEST(UncertaintyRobustness, FixtureLoopsWithDelayFrictionAndSetpointWeight) {
  for (const nlohmann::json& c : robust_reference().at("robustness")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    NormalizedPlant plant = normalized_two_mass(c.at("r").get<double>(), c.at("zeta_z").get<double>(),
                                                c.at("zeta_p").get<double>(), c.at("a").get<double>());
    if (c.at("delay").get<double>() > 0.0) plant.hf.delay_s = c.at("delay").get<double>();
    const VelocityLoop loop(plant, PidGains{c.at("kp").get<double>(), c.at("ki").get<double>(), 0.0, 0.0,
                                            c.at("wp").get<double>(), 0.0});
    const TransferFunction w2(poly_of(c.at("w2_num")), poly_of(c.at("w2_den")));
    const RobustnessResult r = robustness(loop, w2, c.at("ms").get<double>());
    EXPECT_LT(rel_diff(r.rs, c.at("rs").get<double>()), 1e-7);
    EXPECT_LT(rel_diff(r.np, c.at("np").get<double>()), 1e-7);
    EXPECT_LT(rel_diff(r.rp, c.at("rp").get<double>()), 1e-7);
    EXPECT_LT(rel_diff(r.rs_omega, c.at("rs_omega").get<double>()), 1e-3);
    EXPECT_LT(rel_diff(r.np_omega, c.at("np_omega").get<double>()), 1e-3);
    EXPECT_LT(rel_diff(r.rp_omega, c.at("rp_omega").get<double>()), 1e-3);
    // RP >= max(RS, NP) always, and RP <= RS + NP.
    EXPECT_GE(r.rp, std::max(r.rs, r.np) - 1e-12);
    EXPECT_LE(r.rp, r.rs + r.np + 1e-12);
    EXPECT_EQ(r.rp_ok, r.nominally_stable && r.rp < 1.0);
  }
}

TEST(UncertaintyRobustness, BadArgumentsAreInputErrors) {
  const VelocityLoop loop(normalized_two_mass(3.0, 0.01), PidGains{4.63, 0.64, 0.0, 0.0, 1.0, 0.0}, false);
  const TransferFunction w2(Polynomial{2.6, 0.0}, Polynomial{1.0, 15.0});
  expect_input_error([&] { (void)robustness(loop, w2, 1.0); }, "ms", "> 1");
  expect_input_error([&] { (void)robustness(loop, TransferFunction(Polynomial{1.0, 0.0, 0.0}, Polynomial{1.0, 1.0}), 2.0); },
                     "w2", "proper");
  expect_input_error([&] { (void)robustness(loop, TransferFunction(Polynomial{1.0}, Polynomial{1.0, -1.0}), 2.0); },
                     "w2", "stable");
}

// ------------------------------------------------------------------------- largest ω*

TEST(UncertaintyOmegaStar, LargestRobustBandwidthMatchesTheFixture) {
  // r = 3, ζz = 0.01, ζ* = 1, W2 = 2.6 s/(s + 15), M_S = 2: the fixture's brentq roots of
  // rs(ω*) = 1 and rp(ω*) = 1 on its own placement and admissible range.
  const nlohmann::json& f = robust_reference().at("largest_omega_star");
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const TransferFunction w2(Polynomial{2.6, 0.0}, Polynomial{1.0, 15.0});
  UncertaintySearch rs_only;
  rs_only.test = RobustTest::kRobustStability;
  const UncertaintyOmegaStar rs = largest_omega_star_with_uncertainty(plant, 1.0, w2, 2.0, rs_only);
  const UncertaintyOmegaStar rp = largest_omega_star_with_uncertainty(plant, 1.0, w2, 2.0);
  const double omega_max = f.at("omega_max").get<double>();
  const double rs_limit = f.at("rs_limit").get<double>(), rp_limit = f.at("rp_limit").get<double>();
  EXPECT_NEAR(rs.omega_star, rs_limit, 2e-6 * omega_max);
  EXPECT_NEAR(rp.omega_star, rp_limit, 2e-6 * omega_max);
  EXPECT_EQ(rs.limit, rs_limit < omega_max ? UncertaintyLimit::kRobustStability : UncertaintyLimit::kAdmissibleRange);
  EXPECT_LE(rp.omega_star, rs.omega_star);
  EXPECT_TRUE(rp.at_omega_star.rp_ok);
  EXPECT_LT(rp.at_omega_star.rp, 1.0);
  EXPECT_GT(rp.at_omega_star.rp, 0.999);  // the limit is where RP reaches 1
  if (rp.limit == UncertaintyLimit::kRobustPerformance) {
    // Just above the returned ω* the RP test fails.
    const PiGains g = pi_pole_placement(plant.motor(false), rp.omega_star * (1.0 + 1e-4), 1.0).gains;
    const VelocityLoop above(plant, PidGains{g.kp, g.ki, 0.0, 0.0, 1.0, 0.0});
    EXPECT_FALSE(robustness(above, w2, 2.0).rp_ok);
  }
  EXPECT_EQ(to_string(rp.limit).empty(), false);
}

TEST(UncertaintyOmegaStar, AWeightBelowOneEverywhereLeavesTheAdmissibleRange) {
  // |W2| <= 0.05: RS holds for every admissible design, so the range's upper end is returned.
  const NormalizedPlant plant = normalized_two_mass(2.0, 0.02);
  const TransferFunction w2(Polynomial{0.05, 0.0}, Polynomial{1.0, 1.0});
  UncertaintySearch s;
  s.test = RobustTest::kRobustStability;
  const UncertaintyOmegaStar out = largest_omega_star_with_uncertainty(plant, test::kSqrtHalf, w2, 2.0, s);
  EXPECT_EQ(out.limit, UncertaintyLimit::kAdmissibleRange);
  EXPECT_DOUBLE_EQ(out.omega_star, admissible_range(plant, test::kSqrtHalf).omega_max);
}

}  // namespace
}  // namespace servotwin::tuning
