// PI design by partial pole placement (catalog C7.1, C7.3). Where each
// expected value comes from is said per test: "printed" = the dissertation via the catalog,
// "[D]/[R]" = derived by the catalog or the plan from printed formulas, "fixture" =
// tests/data/tuning/tuning_reference.json from tools/reference/tuning_reference.py (numpy
// evaluation of c(s1) and numpy.roots, a different formulation from the C++ remainder method).
// The closed forms 7.36/7.63 and the numeric placement are also checked against each other.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"

namespace servotwin::tuning {
namespace {

using core::Polynomial;
using core::TransferFunction;
using test::frictionless_tf;
using test::kSqrtHalf;
using test::reference;
using test::rel_diff;
using test::root_of;

using test::expect_input_error;

/// E24 demo plant (Im = 1, Il = 8, b = 0.2, k = 8): (1/s)(s² + 0.025 s + 1)/(s² + 0.225 s + 9).
TransferFunction e24_plant() { return {Polynomial{1.0, 0.025, 1.0}, Polynomial{1.0, 0.225, 9.0, 0.0}}; }

TEST(RigidTuning, E24SymmetricOptimumDerived) {
  // E24 [D]: SO on 1/((Im+Il) s (τf s + 1)) with Im + Il = 9, τf = 0.01 ⇒ Kp = 450, Ki = 11250.
  const PiGains g = pi_symmetric_optimum(9.0, 0.01);
  EXPECT_NEAR(g.kp, 450.0, 1e-12 * 450.0);
  EXPECT_NEAR(g.ki, 11250.0, 1e-12 * 11250.0);
  const nlohmann::json& f = reference().at("e24").at("so");
  EXPECT_DOUBLE_EQ(g.kp, f.at("kp").get<double>());
  EXPECT_DOUBLE_EQ(g.ki, f.at("ki").get<double>());
}

TEST(RigidTuning, E24RigidPolePlacementDerivedAndNumeric) {
  // E24 [D]: ξ* = 0.8, ω* ∈ {0.3, 0.6, 2} ⇒ (4.32, 0.81), (8.64, 3.24), (28.8, 36).
  const double expected[3][3] = {{0.3, 4.32, 0.81}, {0.6, 8.64, 3.24}, {2.0, 28.8, 36.0}};
  const TransferFunction rigid(Polynomial{1.0}, Polynomial{9.0, 0.0});  // 1/(J s)
  for (const auto& row : expected) {
    const PiGains g = pi_rigid_pole_placement(9.0, row[0], 0.8);
    EXPECT_NEAR(g.kp, row[1], 1e-12 * row[1]);
    EXPECT_NEAR(g.ki, row[2], 1e-12 * row[2]);
    const PolePlacement n = pi_pole_placement(rigid, row[0], 0.8);
    EXPECT_LT(rel_diff(n.gains.kp, row[1]), 1e-13);
    EXPECT_LT(rel_diff(n.gains.ki, row[2]), 1e-13);
  }
}

TEST(RigidTuning, E24LoopsOnTheTwoMassPlantWithFeedbackFilter) {
  // E24-qual [R]: minimum closed-loop damping with the τf = 0.01 measurement filter:
  // SO 0.0125 (a pair at the antiresonance, −0.012 ± 1.000j), ω* = 0.3 → 0.745, 0.6 → 0.487,
  // 2 → 0.060; the fixture (numpy.roots) to 1e-9.
  HfDynamics filter;
  filter.feedback_filter_s = 0.01;
  const TransferFunction loop_plant = core::series(e24_plant(), filter.feedback_rational());
  const double plan[4] = {0.0125, 0.745, 0.487, 0.060};
  const nlohmann::json& loops = reference().at("e24").at("loops");
  ASSERT_EQ(loops.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const nlohmann::json& f = loops.at(i);
    const PiGains g = i == 0 ? pi_symmetric_optimum(9.0, 0.01) : pi_rigid_pole_placement(9.0, std::vector{0.3, 0.6, 2.0}[i - 1], 0.8);
    const auto [zeta, at] = test::min_damping(closed_loop_polynomial(loop_plant, {g.kp, g.ki, 0.0, 0.0}));
    EXPECT_NEAR(zeta, plan[i], 1e-3) << f.at("name");
    EXPECT_NEAR(zeta, f.at("min_zeta").get<double>(), 1e-9) << f.at("name");
    EXPECT_NEAR(std::abs(at.imag()), f.at("min_zeta_root").at(1).get<double>(), 1e-8) << f.at("name");
  }
}

TEST(ClosedForm, E25UndampedDerivedFixtureAndNumeric) {
  // E25 [D][R]: ξ* = √2/2, ω* = 0.5: r = 1.2 → (0.99993, 0.32765); r = 2 → (2.70364, 0.779412);
  // r = 4 → (10.68979, 2.897059); second pairs −0.1464 ± 1.1354j, −0.99827 ± 1.45640j, real −8.64172, −1.34096.
  const double printed[3][3] = {{1.2, 0.99993, 0.32765}, {2.0, 2.70364, 0.779412}, {4.0, 10.68979, 2.897059}};
  const double tol[3] = {1e-4, 1e-5, 1e-5};
  const nlohmann::json& fixture = reference().at("e25");
  for (std::size_t i = 0; i < 3; ++i) {
    const double r = printed[i][0];
    const PiGains g = pi_closed_form_undamped(0.5, kSqrtHalf, r);
    EXPECT_LT(rel_diff(g.kp, printed[i][1]), tol[i]) << r;
    EXPECT_LT(rel_diff(g.ki, printed[i][2]), tol[i]) << r;
    const nlohmann::json& f = fixture.at(i);
    EXPECT_LT(rel_diff(g.kp, f.at("kp").get<double>()), 1e-12) << r;
    EXPECT_LT(rel_diff(g.ki, f.at("ki").get<double>()), 1e-12) << r;
    const PolePlacement n = pi_pole_placement(frictionless_tf(r, 0.0), 0.5, kSqrtHalf);
    EXPECT_LT(rel_diff(n.gains.kp, g.kp), 1e-13) << r;
    EXPECT_LT(rel_diff(n.gains.ki, g.ki), 1e-13) << r;
    // Second pair: exact division (C++) vs numpy.roots minus the assigned pair (fixture).
    const SecondPair p = second_pair(normalized_two_mass(r, 0.0), g, 0.5, kSqrtHalf);
    const std::complex<double> expected[2] = {root_of(f.at("second_pair").at(0)), root_of(f.at("second_pair").at(1))};
    for (int k = 0; k < 2; ++k) EXPECT_LT(std::abs(p.roots[k] - expected[k]), 1e-9) << r << " root " << k;
    EXPECT_EQ(p.real, r == 4.0);
    EXPECT_TRUE(p.stable);
  }
}

TEST(ClosedForm, E25SecondPairMatchesEquations725And726) {
  // Eqs. 7.25/7.26 (misprint 28 fixed), written out here as the oracle for the undamped plant.
  for (double r : {1.2, 1.5, 2.0, 3.0, 4.0})
    for (double zs : {0.5, kSqrtHalf, 1.0})
      for (double w : {0.1, 0.3, 0.5, 0.8}) {
        const double w2 = w * w, den = w2 * w2 - (2.0 - 4.0 * zs * zs) * w2 + 1.0;
        const double omega2 = std::sqrt((w2 * w2 - w2 + 4.0 * zs * zs * w2 + r * r - r * r * w2) / den);
        const double zeta2 = (r * r - 1.0) * zs * w / (omega2 * den);
        const SecondPair p = second_pair(normalized_two_mass(r, 0.0), pi_closed_form_undamped(w, zs, r), w, zs);
        EXPECT_LT(rel_diff(p.omega, omega2), 1e-12) << r << " " << zs << " " << w;
        EXPECT_LT(rel_diff(p.zeta, zeta2), 1e-12) << r << " " << zs << " " << w;
        const double r_min = zeta2 > 1.0 ? omega2 * (zeta2 - std::sqrt(zeta2 * zeta2 - 1.0)) : omega2;
        EXPECT_LT(rel_diff(p.min_radius, r_min), 1e-10) << r << " " << zs << " " << w;
      }
}

TEST(ClosedForm, E26DampedWithCorrectedOmegaStar) {
  // E26 (misprint 3: ω* = 0.30, not 0.67): ξz = 0.01, r = 3, ξ* = 1 ⇒ Kp = 4.634937, Ki = 0.640260 [R];
  // closed-loop poles −0.3 (double) and −2.10747 ± 1.63480j. Extra: ω* = 0.67 → (6.388085, 1.362933),
  // poles −4.5626, −0.67, −0.67, −0.6654. E26-b: ξ* = 0.8, ω* = 0.5 → (6.117301, 1.491502) [D][R].
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const PiGains g = pi_closed_form_damped(0.30, 1.0, 3.0, 0.01);
  EXPECT_NEAR(g.kp, 4.634937, 1e-6);
  EXPECT_NEAR(g.ki, 0.640260, 1e-6);
  SecondPair p = second_pair(plant, g, 0.30, 1.0);
  EXPECT_NEAR(p.roots[0].real(), -2.10747, 1e-5);
  EXPECT_NEAR(p.roots[0].imag(), 1.63480, 1e-5);
  const PiGains extra = pi_closed_form_damped(0.67, 1.0, 3.0, 0.01);
  EXPECT_NEAR(extra.kp, 6.388085, 1e-6);
  EXPECT_NEAR(extra.ki, 1.362933, 1e-6);
  p = second_pair(plant, extra, 0.67, 1.0);
  EXPECT_TRUE(p.real);
  EXPECT_NEAR(p.roots[0].real(), -0.6654, 1e-4);
  EXPECT_NEAR(p.roots[1].real(), -4.5626, 1e-4);
  EXPECT_LT(p.min_radius, 0.67);  // the second pair is slower than the assigned one: not dominant
  const PiGains b = pi_closed_form_damped(0.5, 0.8, 3.0, 0.01);
  EXPECT_NEAR(b.kp, 6.117301, 1e-6);
  EXPECT_NEAR(b.ki, 1.491502, 1e-6);
  // Fixture: numeric placement by c(s1) evaluation (numpy) and numpy.roots second pairs.
  for (const nlohmann::json& f : reference().at("e26").at("cases")) {
    const double w = f.at("omega_star"), z = f.at("zeta_star");
    const PiGains c = pi_closed_form_damped(w, z, 3.0, 0.01);
    const PolePlacement n = pi_pole_placement(plant.motor(false), w, z);
    EXPECT_LT(rel_diff(c.kp, f.at("kp").get<double>()), 1e-12) << w;
    EXPECT_LT(rel_diff(c.ki, f.at("ki").get<double>()), 1e-12) << w;
    EXPECT_LT(rel_diff(n.gains.kp, c.kp), 1e-12) << w;
    EXPECT_LT(rel_diff(n.gains.ki, c.ki), 1e-12) << w;
    const SecondPair q = second_pair(plant, n.gains, w, z);
    for (int k = 0; k < 2; ++k) EXPECT_LT(std::abs(q.roots[k] - root_of(f.at("second_pair").at(k))), 1e-8) << w;
  }
}

TEST(ClosedForm, E26PrintedRoundedGainsGiveANearDoublePole) {
  // Catalog E26: with the printed (4.63, 0.64) the assigned pole is ≈ −0.299 ± 0.015j and the
  // other pair ≈ −2.106 ± 1.639j; fixture = numpy.roots of the same closed loop.
  const std::vector<std::complex<double>> roots =
      test::sorted_roots(closed_loop_polynomial(frictionless_tf(3.0, 0.01), {4.63, 0.64, 0.0, 0.0}).roots());
  const nlohmann::json& f = reference().at("e26").at("printed_gains_poles");
  ASSERT_EQ(roots.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_LT(std::abs(roots[k] - root_of(f.at(k))), 1e-9) << k;
  EXPECT_NEAR(roots[0].real(), -0.299, 1e-3);
  EXPECT_NEAR(std::abs(roots[0].imag()), 0.015, 1e-3);
}

TEST(ClosedForm, Equation763AgreesWithNumericPlacementEverywhere) {
  // Independent computations of the same quantity: eq. 7.63 (closed form) and the remainder-based
  // numeric placement on the frictionless plant; eq. 7.36 is eq. 7.63 at ξz = 0.
  for (double r : {1.2, 1.5, 2.0, 3.0, 5.0, 8.0})
    for (double zz : {0.0, 0.01, 0.05, 0.2})
      for (double zs : {0.3, kSqrtHalf, 0.8, 1.0, 1.3})
        for (double w : {0.05, 0.2, 0.5, 0.9, 1.4}) {
          const PiGains c = pi_closed_form_damped(w, zs, r, zz);
          const PolePlacement n = pi_pole_placement(frictionless_tf(r, zz), w, zs);
          EXPECT_LT(rel_diff(n.gains.kp, c.kp), 1e-10) << r << " " << zz << " " << zs << " " << w;
          EXPECT_LT(rel_diff(n.gains.ki, c.ki), 1e-10) << r << " " << zz << " " << zs << " " << w;
          if (zz == 0.0) {
            const PiGains u = pi_closed_form_undamped(w, zs, r);
            EXPECT_LT(rel_diff(u.kp, c.kp), 1e-13);
            EXPECT_LT(rel_diff(u.ki, c.ki), 1e-13);
          }
        }
}

TEST(PolePlacement, AssignedPairIsARootAndIsContinuousAcrossCriticalDamping) {
  const TransferFunction plant = normalized_two_mass(2.5, 0.02, 0.08, 0.15).motor(false);
  for (double zs : {0.4, kSqrtHalf, 1.0, 1.6}) {
    const PolePlacement n = pi_pole_placement(plant, 0.6, zs);
    const Polynomial c = closed_loop_polynomial(plant, {n.gains.kp, n.gains.ki, 0.0, 0.0});
    // The assigned pair divides c: c at its roots vanishes relative to c's size there.
    const std::complex<double> s1 = zs < 1.0 ? 0.6 * std::complex<double>(-zs, std::sqrt(1.0 - zs * zs))
                                             : std::complex<double>(0.6 * (-zs + std::sqrt(zs * zs - 1.0)), 0.0);
    double size = 0.0;
    for (double x : c.coefficients()) size = std::max(size, std::abs(x));
    EXPECT_LT(std::abs(c(s1)), 1e-13 * size) << zs;
    EXPECT_LT(n.condition_number, 1e3) << zs;
  }
  // ξ* = 1 is the c(−ω*) = c′(−ω*) = 0 case: the two sides converge to it.
  const PolePlacement at = pi_pole_placement(plant, 0.6, 1.0);
  for (double dz : {1e-6, -1e-6}) {
    const PolePlacement near = pi_pole_placement(plant, 0.6, 1.0 + dz);
    EXPECT_LT(rel_diff(near.gains.kp, at.gains.kp), 1e-5);
    EXPECT_LT(rel_diff(near.gains.ki, at.gains.ki), 1e-5);
  }
  const Polynomial c = closed_loop_polynomial(plant, {at.gains.kp, at.gains.ki, 0.0, 0.0});
  EXPECT_LT(std::abs(c(-0.6)), 1e-13);
  EXPECT_LT(std::abs(c.derivative()(-0.6)), 1e-13);
}

TEST(PolePlacement, E28FrictionPlantGainsDerived) {
  // E28 ([D][R]): K = 1, a = 0.1, ξ = 0.02, ξz = 0.01, ω = 2, ωz = 1, ω* = 0.9:
  // ξ* = √2/2 → Kp = 3.429190, Ki = 1.248403, poles −0.63640 ± 0.63640j, −1.16820 ± 0.42018j;
  // ξ* = 1 → Kp = 3.294913, Ki = 1.061761.
  const NormalizedPlant plant = normalized_two_mass(2.0, 0.01, 0.02, 0.1);
  PolePlacement n = pi_pole_placement(plant.motor(false), 0.9, kSqrtHalf);
  EXPECT_NEAR(n.gains.kp, 3.429190, 1e-6);
  EXPECT_NEAR(n.gains.ki, 1.248403, 1e-6);
  const SecondPair p = second_pair(plant, n.gains, 0.9, kSqrtHalf);
  EXPECT_NEAR(p.roots[0].real(), -1.16820, 1e-5);
  EXPECT_NEAR(p.roots[0].imag(), 0.42018, 1e-5);
  n = pi_pole_placement(plant.motor(false), 0.9, 1.0);
  EXPECT_NEAR(n.gains.kp, 3.294913, 1e-6);
  EXPECT_NEAR(n.gains.ki, 1.061761, 1e-6);
  for (const nlohmann::json& f : reference().at("e28").at("cases")) {
    const double z = f.at("zeta_star");
    const PolePlacement m = pi_pole_placement(plant.motor(false), 0.9, z);
    EXPECT_LT(rel_diff(m.gains.kp, f.at("kp").get<double>()), 1e-12);
    EXPECT_LT(rel_diff(m.gains.ki, f.at("ki").get<double>()), 1e-12);
    const SecondPair q = second_pair(plant, m.gains, 0.9, z);
    for (int k = 0; k < 2; ++k) EXPECT_LT(std::abs(q.roots[k] - root_of(f.at("second_pair").at(k))), 1e-9);
  }
}

TEST(PolePlacement, GenericThreeModePlantWithLagAndPidFixture) {
  // No closed form exists: fixture only (numpy c(s1)/c(−ω*)/two-real-roots evaluation).
  const nlohmann::json& g = reference().at("generic");
  const TransferFunction plant(Polynomial(g.at("num").get<std::vector<double>>()),
                               Polynomial(g.at("den").get<std::vector<double>>()));
  for (const nlohmann::json& f : g.at("cases")) {
    const PolePlacement n = pi_pole_placement(plant, f.at("omega_star"), f.at("zeta_star"), f.at("kd"), f.at("tau"));
    EXPECT_LT(rel_diff(n.gains.kp, f.at("kp").get<double>()), 1e-10) << f.dump();
    EXPECT_LT(rel_diff(n.gains.ki, f.at("ki").get<double>()), 1e-10) << f.dump();
  }
}

/// A physical plant: 0.2 mm/(N·m·s) rigid gain, ωz = 2π·20, ωn = 2π·45, a second mode and a lag.
fit::PlantModel physical_model(double gain_scale, double time_scale) {
  fit::PlantModel m;
  m.gain = 250.0 * gain_scale * time_scale;  // K/s keeps its form when time is scaled: K·ts
  m.rigid_pole_rad_s = 3.0 * time_scale;
  m.modes = {{{2.0 * std::numbers::pi * 20.0 * time_scale, 0.03}, {2.0 * std::numbers::pi * 45.0 * time_scale, 0.06}},
             {{2.0 * std::numbers::pi * 160.0 * time_scale, 0.02}, {2.0 * std::numbers::pi * 210.0 * time_scale, 0.03}}};
  m.lag_pole_rad_s = 4000.0 * time_scale;
  return m;
}

TEST(UnitInvariance, GainAndTimeScalingChangeOnlyThePhysicalGains) {
  // Independent check of the de-normalization: the numeric placement run directly on the
  // physical design model (physical ω*) must give to_physical() of the normalized design.
  const NormalizedPlant base = normalize(physical_model(1.0, 1.0));
  const PolePlacement design = pi_pole_placement(base.motor(false), 0.45, 0.8);
  for (const auto& [gain_scale, time_scale] : {std::pair{1.0, 1.0}, std::pair{1000.0, 1.0}, std::pair{1e-3, 10.0}}) {
    const fit::PlantModel model = physical_model(gain_scale, time_scale);
    const NormalizedPlant p = normalize(model);
    EXPECT_LT(rel_diff(p.r, base.r), 1e-15);
    EXPECT_LT(rel_diff(p.zeta_p, base.zeta_p), 1e-15);
    EXPECT_LT(rel_diff(p.a, base.a), 1e-15);
    EXPECT_LT(rel_diff(p.motor_inertia * gain_scale, base.motor_inertia), 1e-14);
    const PolePlacement n = pi_pole_placement(p.motor(false), 0.45, 0.8);
    EXPECT_LT(rel_diff(n.gains.kp, design.gains.kp), 1e-12);
    EXPECT_LT(rel_diff(n.gains.ki, design.gains.ki), 1e-12);
    const PiGains phys = to_physical(n.gains, p);
    const PiGains phys_base = to_physical(design.gains, base);
    EXPECT_LT(std::abs(phys.kp * gain_scale / time_scale / phys_base.kp - 1.0), 1e-12);
    EXPECT_LT(std::abs(phys.ki * gain_scale / (time_scale * time_scale) / phys_base.ki - 1.0), 1e-12);
    // The physical design model K'/(s + a)·mode 1 with K' = K·(ωz2/ω2)²/p.
    const fit::Mode& m2 = model.modes[1];
    fit::PlantModel physical_design = model;
    physical_design.modes.resize(1);
    physical_design.lag_pole_rad_s.reset();
    physical_design.gain *= std::pow(m2.antiresonance.omega_rad_s / m2.resonance.omega_rad_s, 2) / *model.lag_pole_rad_s;
    const PolePlacement direct =
        pi_pole_placement(physical_design.transfer_function(), p.physical_frequency(0.45), 0.8);
    EXPECT_LT(std::abs(direct.gains.kp / phys.kp - 1.0), 1e-10);
    EXPECT_LT(std::abs(direct.gains.ki / phys.ki - 1.0), 1e-10);
    EXPECT_LT(std::abs(to_normalized(phys, p).kp / n.gains.kp - 1.0), 1e-15);
    EXPECT_LT(std::abs(to_normalized(phys, p).ki / n.gains.ki - 1.0), 1e-15);
  }
}

TEST(PolePlacement, BadInputsNameTheParameter) {
  const TransferFunction plant = frictionless_tf(2.0, 0.01);
  expect_input_error([&] { (void)pi_pole_placement(plant, 0.0, 0.8); }, "omega_star", "expected a bandwidth > 0");
  expect_input_error([&] { (void)pi_pole_placement(plant, -1.0, 0.8); }, "omega_star", "got -1");
  expect_input_error([&] { (void)pi_pole_placement(plant, 0.5, 0.0); }, "zeta_star", "expected a damping ratio > 0");
  expect_input_error([&] { (void)pi_pole_placement(plant, std::nan(""), 0.8); }, "omega_star", "bandwidth");
  expect_input_error([&] { (void)pi_pole_placement(plant, 0.5, 0.8, 0.0, -0.1); }, "tau",
                     "expected a derivative filter time constant >= 0");
  expect_input_error([&] { (void)pi_pole_placement(plant, 0.5, 0.8, std::numeric_limits<double>::infinity()); }, "kd", "expected a finite value");
  const TransferFunction constant(Polynomial{2.0}, Polynomial{1.0});
  expect_input_error([&] { (void)pi_pole_placement(constant, 0.5, 0.8); }, "plant", "degree < 2");
  // The pair exactly on the plant's zeros (ξ* = ξz, ω* = 1): singular.
  expect_input_error([&] { (void)pi_pole_placement(plant, 1.0, 0.01); }, "omega_star", "cannot be placed");
  expect_input_error([] { (void)pi_closed_form_damped(1.0, 0.01, 2.0, 0.01); }, "omega_star",
                     "coincides with the antiresonance zeros");
  expect_input_error([] { (void)pi_closed_form_undamped(0.5, 0.7, 1.0); }, "r", "expected a resonance ratio");
  expect_input_error([] { (void)pi_closed_form_damped(0.5, 0.7, 2.0, -0.1); }, "zeta_z", "damping ratio >= 0");
  expect_input_error([] { (void)pi_symmetric_optimum(0.0, 0.01); }, "inertia", "expected an inertia > 0");
  expect_input_error([] { (void)pi_symmetric_optimum(1.0, 0.0); }, "lag_time_constant", "time constant");
  expect_input_error([] { (void)pi_rigid_pole_placement(-1.0, 1.0, 0.7); }, "inertia", "inertia");
  const NormalizedPlant two_mass = normalized_two_mass(3.0, 0.01);
  expect_input_error([&] { (void)second_pair(two_mass, {1.0, 1.0}, 0.3, 1.0); }, "gains", "do not place the pair");
  // Near (not on) the zeros: solvable but flagged by the condition number.
  EXPECT_GT(pi_pole_placement(plant, 1.0, 0.0101).condition_number, 50.0);
}

}  // namespace
}  // namespace servotwin::tuning
