// Admissible bandwidth range, the C7.4 limit tables and design rules, and PID by virtual inertia
// (catalog C7.3–C7.6; examples E25-a, the C7.4 table, E26, E-PID, A5).
// "Printed" values are the dissertation's as restated in the catalog (C7.4 tables to the 3
// printed digits, E25-a to 4); "fixture" values come from tools/reference/tuning_reference.py
// (dense grid of numpy.roots-based tests + 80 bisection steps, an independent implementation).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <string>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {
namespace {

using test::kSqrtHalf;
using test::reference;
using test::rel_diff;
using test::root_of;

using test::expect_input_error;

constexpr double kNotPrinted = std::numeric_limits<double>::quiet_NaN();

RangeLimit limit_from_fixture(const std::string& name) {
  static const std::map<std::string, RangeLimit> names = {{"none", RangeLimit::kNone},
                                                          {"full", RangeLimit::kFullBandwidth},
                                                          {"ki", RangeLimit::kIntegralGain},
                                                          {"kp", RangeLimit::kProportionalGain},
                                                          {"stability", RangeLimit::kStability},
                                                          {"radius", RangeLimit::kSecondPairRadius}};
  return names.at(name);
}

/// Compares a range with a fixture entry; the limit names are compared unless the end sits at
/// ω* = 1, where "full bandwidth" and "radius" coincide (the radius equals ω* there). The
/// tolerances used below (1e-9) are set by the fixture: for ξ* = 1 the radius boundary is a
/// near-triple root (−ω* double, the second pair's slow root → −ω*), where numpy.roots keeps
/// ~10 digits (the observed differences are 2–3e-10 there, below 1e-10 elsewhere).
void expect_range(const AdmissibleRange& range, const nlohmann::json& f, double tol, const std::string& label) {
  EXPECT_NEAR(range.omega_min, f.at("omega_min").get<double>(), tol) << label;
  EXPECT_NEAR(range.omega_max, f.at("omega_max").get<double>(), tol) << label;
  EXPECT_EQ(range.lower, limit_from_fixture(f.at("lower"))) << label;
  if (f.at("omega_max").get<double>() < 1.0 - 1e-6) {
    EXPECT_EQ(range.upper, limit_from_fixture(f.at("upper"))) << label << " " << to_string(range.upper);
  }
}

TEST(Limits, C74TablesPrintedAndFixture) {
  // C7.4 [D] printed to 3 digits: ξ2max for ξ* = √2/2 and 1 (rows up to r = 2.5 resp. √5)
  // and ω*max for every r.
  const double r_values[10] = {1.2, 1.5, std::sqrt(3.0), 2.0, std::sqrt(5.0), 2.5, 3.0, 4.0, 5.0, 8.0};
  const double xi2_printed[2][10] = {{0.168, 0.449, 0.707, 1.061, 1.414, 1.856, kNotPrinted, kNotPrinted, kNotPrinted, kNotPrinted},
                                     {0.133, 0.348, 0.528, 0.761, 1.0, kNotPrinted, kNotPrinted, kNotPrinted, kNotPrinted, kNotPrinted}};
  const double omega_printed[2][10] = {{1, 1, 1, 0.929, 0.813, 0.762, 0.716, 0.681, 0.666, 0.652},
                                       {1, 1, 1, 1, 1, 0.766, 0.681, 0.627, 0.607, 0.588}};
  const nlohmann::json& fixture = reference().at("c74_tables");
  ASSERT_EQ(fixture.size(), 20u);
  for (int k = 0; k < 2; ++k) {
    const double zs = k == 0 ? kSqrtHalf : 1.0;
    for (int i = 0; i < 10; ++i) {
      const NormalizedPlant plant = normalized_two_mass(r_values[i], 0.0);
      const nlohmann::json& f = fixture.at(static_cast<std::size_t>(10 * k + i));
      const DampingLimit d = max_second_pair_damping(plant, zs);
      const AdmissibleRange range = admissible_range(plant, zs);
      const std::string label = "zeta* " + std::to_string(zs) + " r " + std::to_string(r_values[i]);
      if (!std::isnan(xi2_printed[k][i])) {
        EXPECT_NEAR(d.zeta2_max, xi2_printed[k][i], 1e-3) << label;
      }
      EXPECT_NEAR(range.omega_max, omega_printed[k][i], 1e-3) << label;
      EXPECT_LT(rel_diff(d.zeta2_max, f.at("xi2_max").get<double>()), 1e-7) << label;
      EXPECT_NEAR(d.omega_star, f.at("xi2_max_at").get<double>(), 1e-4) << label;
      EXPECT_NEAR(range.omega_max, f.at("omega_max").get<double>(), 1e-9) << label;
      if (f.at("omega_max").get<double>() < 1.0 - 1e-6) {
        EXPECT_EQ(range.upper, limit_from_fixture(f.at("limited_by"))) << label;
      }
      EXPECT_EQ(range.omega_min, 0.0) << label;  // frictionless: smooth closing from ω* = 0
      EXPECT_EQ(range.lower, RangeLimit::kNone) << label;
    }
  }
}

TEST(Limits, E26PlantRangeIsBelowThePrintedOmegaStar) {
  // E26 extra: at ω* = 0.67 the second pair has a real root at −0.6654 — slower than the
  // assigned pair — so the admissible range ends just below 0.67 (fixture: 0.668477).
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const nlohmann::json& f = reference().at("e26").at("admissible");
  for (const auto& [key, value] : f.items()) {
    const AdmissibleRange range = admissible_range(plant, std::stod(key));
    expect_range(range, value, 1e-9, "E26 zeta* " + key);
  }
  const AdmissibleRange one = admissible_range(plant, 1.0);
  EXPECT_LT(one.omega_max, 0.67);
  EXPECT_GT(one.omega_max, 0.30);  // the corrected E26 design (ω* = 0.30) is admissible
  EXPECT_EQ(one.upper, RangeLimit::kSecondPairRadius);
}

TEST(Limits, FrictionPlantsHaveALowerBandwidthLimit) {
  // Catalog C7.6: with friction Kp → −r²a as ω* → 0, so ω* must exceed a lower limit where Kp
  // turns positive. Table-5.1 normalized (E-fric) and the E28 plant; fixture ranges to 1e-8.
  const NormalizedPlant table51 = normalized_two_mass(3.0, 0.06, 0.15, 0.2);
  for (const auto& [key, value] : reference().at("e_fric").at("admissible").items())
    expect_range(admissible_range(table51, std::stod(key)), value, 1e-9, "table-5.1 zeta* " + key);
  const NormalizedPlant e28 = normalized_two_mass(2.0, 0.01, 0.02, 0.1);
  for (const auto& [key, value] : reference().at("e28").at("admissible").items())
    expect_range(admissible_range(e28, std::stod(key)), value, 1e-9, "E28 zeta* " + key);
  // At tiny ω* the numeric placement indeed gives Kp ≈ −r²a (C7.6).
  const PolePlacement tiny = pi_pole_placement(table51.motor(false), 1e-6, 1.0);
  EXPECT_NEAR(tiny.gains.kp, -9.0 * 0.2, 1e-4);
}

TEST(Limits, FrictionlessGainLimitFromRootsAgreesWithTheScan) {
  // Eq. 7.63's Ki numerator has a root in (0, 1] for these plants (fixture: numpy.roots). The
  // admissible range of the exactly frictionless plant uses the root; a plant perturbed by 1e-10
  // in ζp takes the general scan path: both must agree with the fixture's ranges.
  for (const nlohmann::json& f : reference().at("gain_root_cases")) {
    const double r = f.at("r"), zz = f.at("zeta_z"), zs = f.at("zeta_star");
    EXPECT_LT(rel_diff(frictionless_gain_limit(r, zz, zs), f.at("gain_limit").get<double>()), 1e-12);
    const NormalizedPlant exact = normalized_two_mass(r, zz);
    const NormalizedPlant perturbed = normalized_two_mass(r, zz, r * zz * (1.0 + 1e-10));
    expect_range(admissible_range(exact, zs), f.at("admissible"), 1e-9, "exact r " + std::to_string(r));
    expect_range(admissible_range(perturbed, zs), f.at("admissible"), 1e-7, "perturbed r " + std::to_string(r));
  }
  // Undamped plants with ξ* >= √2/2: positive gains on all of (0, 1] (catalog C7.3).
  for (double r : {1.2, 2.0, 5.0}) EXPECT_EQ(frictionless_gain_limit(r, 0.0, kSqrtHalf), 1.0);
}

TEST(Limits, E25aFullBandwidthRatioAndAdvice) {
  // E25-a [V]: r_max = sqrt(4ξ* + 1) = 1.957, 2.049, 2.236 for ξ* = √2/2, 0.8, 1 (catalog, 3
  // decimals; the plan's "1.9572" is off in the 4th digit: sqrt(2√2 + 1) = 1.95664).
  EXPECT_NEAR(advise(2.0, kSqrtHalf).r_full_bandwidth, 1.957, 5e-4);
  EXPECT_NEAR(advise(2.0, 0.8).r_full_bandwidth, 2.049, 5e-4);
  EXPECT_NEAR(advise(2.0, 1.0).r_full_bandwidth, 2.236, 5e-4);
  EXPECT_DOUBLE_EQ(advise(2.0, kSqrtHalf).r_full_bandwidth, std::sqrt(2.0 * std::sqrt(2.0) + 1.0));
  // ... and the admissible range reaches ω* = 1 exactly up to that ratio (independent: the scan).
  for (double zs : {kSqrtHalf, 0.8, 1.0}) {
    const double r_full = std::sqrt(4.0 * zs + 1.0);
    EXPECT_EQ(admissible_range(normalized_two_mass(r_full * 0.999, 0.0), zs).upper, RangeLimit::kFullBandwidth);
    EXPECT_LT(admissible_range(normalized_two_mass(r_full * 1.01, 0.0), zs).omega_max, 0.999);
  }
  // C7.4 classes with the damping-based range ⟨√3, √5⟩ (misprint 21).
  EXPECT_EQ(advise(1.25, kSqrtHalf).kind, RatioClass::kUncontrollable);
  EXPECT_NE(advise(1.25, kSqrtHalf).verdict.find("use passive methods (shaping)"), std::string::npos);
  EXPECT_EQ(advise(1.5, kSqrtHalf).kind, RatioClass::kUnderdamped);
  EXPECT_NE(advise(1.5, kSqrtHalf).verdict.find("cannot be damped to xi >= 0.707 by PI"), std::string::npos);
  EXPECT_EQ(advise(std::sqrt(3.0), kSqrtHalf).kind, RatioClass::kSweetSpot);
  EXPECT_EQ(advise(2.0, kSqrtHalf).kind, RatioClass::kSweetSpot);
  EXPECT_NE(advise(2.0, kSqrtHalf).verdict.find("PI sweet spot"), std::string::npos);
  EXPECT_EQ(advise(std::sqrt(5.0), kSqrtHalf).kind, RatioClass::kSweetSpot);
  EXPECT_EQ(advise(2.3, kSqrtHalf).kind, RatioClass::kSluggish);
  EXPECT_NE(advise(2.3, kSqrtHalf).verdict.find("PI sluggish"), std::string::npos);
  EXPECT_TRUE(advise(1.9, kSqrtHalf).full_bandwidth);
  EXPECT_FALSE(advise(2.0, kSqrtHalf).full_bandwidth);
  // Equal-damping bound (C7.4): r = √3 gives exactly ξ2max = √2/2 for ξ* = √2/2.
  EXPECT_NEAR(max_second_pair_damping(normalized_two_mass(std::sqrt(3.0), 0.0), kSqrtHalf).zeta2_max, kSqrtHalf, 1e-7);
}

TEST(Limits, A5BeltAxis) {
  // A5 (printed fz = 4.5 Hz, fn = 12.1 Hz, r = 2.7): r = 2.6889, "sluggish", Kd_n = (r²−1)/3 − 1 = 1.076708 [D].
  const double r = 12.1 / 4.5;
  EXPECT_NEAR(r, 2.6889, 1e-4);
  EXPECT_EQ(advise(r, kSqrtHalf).kind, RatioClass::kSluggish);
  EXPECT_NEAR(virtual_inertia_kd(r, 2.0), 1.076708, 1e-6);
  EXPECT_LT(rel_diff(virtual_inertia_kd(r, 2.0), reference().at("a5").at("kd").get<double>()), 1e-14);
}

TEST(Pid, EPidVirtualInertiaIdealDerivative) {
  // E-PID [R]: r = 4, r̄ = 2, ξ* = √2/2, ω* = 0.5, ideal D ⇒ Kd = 4, Kp = 13.518218,
  // Ki = 3.897059; closed-loop poles = E25-c's (−0.35355 ± 0.35355j, −0.99827 ± 1.45640j).
  const NormalizedPlant plant = normalized_two_mass(4.0, 0.0);
  const PidDesign d = pid_design(plant, 2.0, 0.5, kSqrtHalf, 0.0);
  EXPECT_DOUBLE_EQ(d.gains.kd, 4.0);
  EXPECT_NEAR(d.gains.kp, 13.518218, 1e-6);
  EXPECT_NEAR(d.gains.ki, 3.897059, 1e-6);
  EXPECT_EQ(d.gains.wd, 0.0);
  EXPECT_TRUE(d.closed_loop_stable);
  EXPECT_TRUE(d.controller_minimum_phase);
  EXPECT_TRUE(d.warnings.empty());
  // Virtual inertia identity (C7.5): Kp = K̄p(Kd + 1) with the r̄ closed form (eq. 7.36).
  const PiGains bar = pi_closed_form_undamped(0.5, kSqrtHalf, 2.0);
  EXPECT_LT(rel_diff(d.gains.kp, 5.0 * bar.kp), 1e-12);
  EXPECT_LT(rel_diff(d.gains.ki, 5.0 * bar.ki), 1e-12);
  const SecondPair p = second_pair(plant, {d.gains.kp, d.gains.ki}, 0.5, kSqrtHalf, d.gains.kd);
  EXPECT_NEAR(p.roots[0].real(), -0.99827, 1e-5);
  EXPECT_NEAR(p.roots[0].imag(), 1.45640, 1e-5);
  const nlohmann::json& f = reference().at("e_pid");
  EXPECT_LT(rel_diff(d.gains.kp, f.at("kp").get<double>()), 1e-12);
  EXPECT_LT(rel_diff(d.gains.ki, f.at("ki").get<double>()), 1e-12);
  const std::vector<std::complex<double>> roots =
      test::sorted_roots(closed_loop_polynomial(plant.motor(false), d.gains).roots());
  for (std::size_t k = 0; k < 4; ++k) EXPECT_LT(std::abs(roots[k] - root_of(f.at("poles_ideal").at(k))), 1e-9);
  // The admissible range with the ideal derivative equals the r̄ = 2 PI range (C7.5, table: 0.929).
  EXPECT_NEAR(admissible_range(plant, kSqrtHalf, 4.0).omega_max, admissible_range(normalized_two_mass(2.0, 0.0), kSqrtHalf).omega_max,
              1e-9);
}

TEST(Pid, EPidWithDerivativeFilter) {
  // τ = 0.01: the pair is placed with the filter included (fixture: numpy placement on the 5th-order
  // loop), and the ideal-derivative gains with the filter added keep the poles within 3 %.
  const NormalizedPlant plant = normalized_two_mass(4.0, 0.0);
  const PidDesign d = pid_design(plant, 2.0, 0.5, kSqrtHalf, 0.01);
  const nlohmann::json& f = reference().at("e_pid");
  EXPECT_LT(rel_diff(d.gains.kp, f.at("kp_tau").get<double>()), 1e-12);
  EXPECT_LT(rel_diff(d.gains.ki, f.at("ki_tau").get<double>()), 1e-12);
  const std::vector<std::complex<double>> roots =
      test::sorted_roots(closed_loop_polynomial(plant.motor(false), d.gains).roots());
  ASSERT_EQ(roots.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) EXPECT_LT(std::abs(roots[k] / root_of(f.at("poles_tau").at(k)) - 1.0), 1e-9);
  const std::vector<std::complex<double>> ideal_with_filter = test::sorted_roots(
      closed_loop_polynomial(plant.motor(false), {f.at("kp").get<double>(), f.at("ki").get<double>(), 4.0, 0.01}).roots());
  for (std::size_t k = 0; k < 4; ++k)
    EXPECT_LT(std::abs(ideal_with_filter[k] / root_of(f.at("poles_ideal").at(k)) - 1.0), 0.03) << k;
  EXPECT_DOUBLE_EQ(default_derivative_time_constant(4.0, 0.5), 0.25);  // 1/max(r, 5ω*)
  EXPECT_DOUBLE_EQ(default_derivative_time_constant(2.0, 0.6), 1.0 / 3.0);
}

TEST(Pid, NegativeKdIsRefusedUnlessAllowed) {
  const NormalizedPlant plant = normalized_two_mass(1.6, 0.02);
  EXPECT_LT(virtual_inertia_kd(1.6, 2.0), 0.0);
  expect_input_error([&] { (void)pid_design(plant, 2.0, 0.5, kSqrtHalf, 0.01); }, "r_target",
                     "needs Kd = -0.48 < 0 here (r = 1.6 is below the target r = 2): that is positive acceleration "
                     "feedback");
  const PidDesign d = pid_design(plant, 2.0, 0.5, kSqrtHalf, 0.01, true);
  EXPECT_NEAR(d.gains.kd, -0.48, 1e-15);
  EXPECT_FALSE(d.controller_minimum_phase);  // Kd < 0 with Kp, Ki > 0: a right-half-plane zero
  ASSERT_FALSE(d.warnings.empty());
  EXPECT_NE(d.warnings.front().find("allowed on request"), std::string::npos);
}

TEST(Pid, DenormalizationOfPidGains) {
  NormalizedPlant p = normalized_two_mass(4.0, 0.0);
  p.omega_z = 50.0;
  p.motor_inertia = 0.002;
  const PidGains n{13.5, 3.9, 4.0, 0.01, 0.5, 0.0};
  const PidGains g = to_physical(n, p);
  EXPECT_DOUBLE_EQ(g.kp, 13.5 * 0.002 * 50.0);
  EXPECT_DOUBLE_EQ(g.ki, 3.9 * 0.002 * 2500.0);
  EXPECT_DOUBLE_EQ(g.kd, 4.0 * 0.002);
  EXPECT_DOUBLE_EQ(g.tau, 0.01 / 50.0);
  EXPECT_EQ(g.wp, 0.5);
  const PidGains back = to_normalized(g, p);
  EXPECT_LT(rel_diff(back.kp, n.kp) + rel_diff(back.ki, n.ki) + rel_diff(back.kd, n.kd) + rel_diff(back.tau, n.tau), 1e-15);
}

TEST(Limits, BadInputsNameTheParameter) {
  const NormalizedPlant plant = normalized_two_mass(2.0, 0.01);
  expect_input_error([&] { (void)admissible_range(plant, 0.0); }, "zeta_star", "expected a damping ratio > 0");
  expect_input_error([&] { (void)admissible_range(plant, 0.7, -1.0); }, "kd", "expected Kd > -1");
  expect_input_error([&] { (void)max_second_pair_damping(plant, -0.5); }, "zeta_star", "damping ratio");
  expect_input_error([] { (void)advise(1.0, 0.7); }, "r", "expected a resonance ratio");
  expect_input_error([] { (void)advise(2.0, 0.0); }, "zeta_star", "damping ratio");
  expect_input_error([] { (void)virtual_inertia_kd(3.0, 1.0); }, "r_target", "expected a resonance ratio");
  expect_input_error([] { (void)default_derivative_time_constant(2.0, 0.0); }, "omega_star", "bandwidth");
  expect_input_error([&] { (void)pid_design(plant, 2.0, 0.5, 0.7, -0.01); }, "tau", "time constant");
  expect_input_error([] { (void)frictionless_gain_limit(2.0, 0.01, 0.0); }, "zeta_star", "damping ratio");
  EXPECT_EQ(to_string(RangeLimit::kSecondPairRadius), "second pair radius");
  EXPECT_EQ(to_string(RangeLimit::kProportionalGain), "Kp <= 0");
}

}  // namespace
}  // namespace servotwin::tuning
