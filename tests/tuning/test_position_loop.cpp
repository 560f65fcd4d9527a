// P position loop over a velocity loop (catalog C7.10). Expected values: eq. 7.110 (closed
// form, derivation in position_loop.hpp) against the TF algebra, roots for the Routh verdicts,
// brute-force sampling of Δ for the exact worst case, and tests/data/tuning/robust_reference.json
// (tools/reference/tuning_robust_reference.py: dense grid + brentq in scipy) for E27-Kpp. The printed
// E27 Kpp values (RS 2, nominal 0.3, RP 0.11) are NOT reproduced (catalog misprint 26); the fixture
// holds our numbers, and the tests below show where the printed ones come from.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "fixture.hpp"
#include "json_fixture.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/tuning/normalized_plant.hpp"
#include "servotwin/tuning/pi_design.hpp"
#include "servotwin/tuning/position_loop.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {
namespace {

using core::Polynomial;
using core::TransferFunction;
using test::expect_input_error;
using test::rel_diff;

const nlohmann::json& e27_fixture() {
  static const nlohmann::json j =
      test_support::read_json_fixture("tuning/robust_reference.json", "tuning_robust_reference.py").at("e27");
  return j;
}

const TransferFunction& e27_weight() {
  static const TransferFunction w2(Polynomial{2.6, 0.0}, Polynomial{1.0, 15.0});
  return w2;
}

/// The E27 velocity loop: PI (4.63, 0.64) 1-DoF on r = 3, ζz = 0.01, without the delay (W2 covers it).
const VelocityLoop& e27_loop() {
  static const VelocityLoop loop(normalized_two_mass(3.0, 0.01), PidGains{4.63, 0.64, 0.0, 0.0, 1.0, 0.0}, false);
  return loop;
}

double max_rel_diff(std::complex<double> a, std::complex<double> b) { return std::abs(a - b) / std::abs(b); }

// ------------------------------------------------------------------------- E27-Kpp

TEST(PositionLoopE27, KppBoundsMatchTheFixtureAndTheirOrdering) {
  const nlohmann::json& f = e27_fixture().at("position");
  const PositionLoop p(functions_of(e27_loop()), e27_weight());
  const PositionLoopDesign d = p.design();
  EXPECT_LT(rel_diff(d.kpp_nominal, f.at("kpp_nominal").get<double>()), 1e-5);
  EXPECT_LT(rel_diff(d.kpp_rs, f.at("kpp_rs").get<double>()), 1e-5);
  EXPECT_LT(rel_diff(d.kpp_rp_exact, f.at("kpp_rp_exact").get<double>()), 1e-5);
  // The sufficient test is decided at the grid's first point (ω = 1e-3 in both codes).
  EXPECT_LT(std::abs(d.kpp_rp - f.at("kpp_rp").get<double>()) / f.at("kpp_rp").get<double>(), 1e-4);
  EXPECT_LT(rel_diff(d.j1, f.at("j1").get<double>()), 1e-6);
  EXPECT_LT(rel_diff(d.j2, f.at("j2").get<double>()), 1e-6);
  // Plan §2 E27-Kpp: Kpp_RP < Kpp_nominal < Kpp_RS.
  EXPECT_LT(d.kpp_rp, d.kpp_nominal);
  EXPECT_LT(d.kpp_nominal, d.kpp_rs);
  EXPECT_LE(d.peak_load_tracking, 1.0 + 1e-8);
  // Not the printed ones (misprint 26): at the printed nominal 0.3 the load-position peak is 1.28.
  EXPECT_NEAR(p.load_tracking_peak(0.3), f.at("peak_at_0_3").get<double>(), 1e-6);
  EXPECT_GT(p.load_tracking_peak(0.3), 1.25);
  EXPECT_GT(std::abs(d.kpp_rs - 2.0), 0.3);
}

TEST(PositionLoopE27, SignOfThePrintedRobustStabilityFormDoesNotMatterFor1DoF) {
  // Derived W2 (T Spn + Tpn) = W2 T (s + Kpp)/(s + Kpp T) and printed W2 Tvn Spn − W2 Tpn =
  // W2 T (s − Kpp)/(s + Kpp T) for a 1-DoF loop (Tvn = T): |jω + Kpp| = |jω − Kpp|, so the two have
  // the same modulus at every frequency and the catalog's sign slip is harmless there. For a 2-DoF
  // loop (Tvn ≠ T) they differ.
  const nlohmann::json& f = e27_fixture().at("position");
  EXPECT_LT(rel_diff(f.at("kpp_rs").get<double>(), f.at("kpp_rs_printed_form").get<double>()), 1e-9);
  const PositionLoop p(functions_of(e27_loop()), e27_weight());
  EXPECT_NEAR(p.robust_stability_peak(2.0), f.at("rs_at_2").get<double>(), 1e-7);
  for (double w : {0.01, 0.3, 1.0, 7.0}) {
    EXPECT_NEAR(std::abs(p.robust_stability_function(w, 1.0)), std::abs(p.printed_robust_stability_function(w, 1.0)),
                1e-13);
  }
  const VelocityLoop two_dof(normalized_two_mass(3.0, 0.01), PidGains{4.63, 0.64, 0.0, 0.0, 0.3, 0.0}, false);
  const PositionLoop q(functions_of(two_dof), e27_weight());
  EXPECT_GT(std::abs(std::abs(q.robust_stability_function(0.3, 1.0)) - std::abs(q.printed_robust_stability_function(0.3, 1.0))),
            1e-3);
}

TEST(PositionLoopE27, SufficientRpBoundIsSetByTheGridStart) {
  // Near ω = 0 the printed inequality's margin is −2(k/p)Kpp ω + ω²/(2Kpp) + …, W2 = k s/(s + p): it
  // fails for every Kpp below ω ≈ 4 (k/p) Kpp², so the largest passing Kpp is ≈ sqrt(ω_min p/(4k)).
  // ω_min = 1e-3 gives 0.038 (the catalog's "≈ 0.035"); ω_min ≈ 0.01 gives ≈ 0.12, close to the
  // printed 0.11 — the printed RP value is consistent with a grid starting near 0.01.
  for (double omega_min : {1e-3, 1e-2}) {
    PositionLoopOptions o;
    o.omega_min = omega_min;
    const PositionLoop p(functions_of(e27_loop()), e27_weight(), o);
    const double predicted = std::sqrt(omega_min * 15.0 / (4.0 * 2.6));
    EXPECT_NEAR(p.design().kpp_rp, predicted, 0.1 * predicted) << "omega_min = " << omega_min;
  }
  // The exact worst case has no such artefact: at Kpp = 0.1 it is below 1 everywhere while the
  // sufficient margin is negative at ω = 1e-4.
  const PositionLoop p(functions_of(e27_loop()), e27_weight());
  EXPECT_LT(p.sufficient_rp_margin(1e-4, 0.1), 0.0);
  EXPECT_LT(p.worst_case_peak(0.1), 1.0 + 1e-9);
}

TEST(PositionLoopE27, ExactWorstCaseAgreesWithSamplingDelta) {
  // max over |Δ| <= 1 of |Tp(Δ)| is attained on |Δ| = 1 (maximum modulus; Tp analytic in Δ on the
  // disk when RS holds pointwise). Sample 7200 angles and compare with the closed-form disk.
  const PositionLoop p(functions_of(e27_loop()), e27_weight());
  const VelocityLoop& v = e27_loop();
  for (double kpp : {0.05, 0.25, 1.0}) {
    for (double w : {1e-3, 0.1, 0.35, 1.0, 3.0, 10.0}) {
      const std::complex<double> s(0.0, w), tv = v.motor_tracking(w), t = v.complementary(w);
      const std::complex<double> w2 = e27_weight().frequency_response(w);
      double sampled = 0.0;
      for (int i = 0; i < 7200; ++i) {
        const std::complex<double> d = std::polar(1.0, 2.0 * std::numbers::pi * i / 7200.0);
        sampled = std::max(sampled, std::abs(kpp * tv * (1.0 + d * w2) / (s + kpp * tv + d * w2 * (s * t + kpp * tv))));
      }
      const double exact = p.worst_case_motor_tracking(w, kpp);
      EXPECT_GE(exact, sampled * (1.0 - 1e-12));
      EXPECT_NEAR(exact, sampled, 1e-6 * exact) << "kpp " << kpp << " w " << w;
      // The printed inequality is the triangle bound of the same quantity.
      if (p.sufficient_rp_margin(w, kpp) >= 0.0) {
        EXPECT_LE(exact, 1.0 + 1e-12);
      }
    }
  }
}

TEST(PositionLoopE27, RouthStabilityAgreesWithTheRootsOfTheCascade) {
  // The E27 loop with its delay D = 0.15 inside (Padé(6) in the rational closed loop): the cascade
  // loses stability at a finite Kpp, which the sweep must cross.
  NormalizedPlant delayed = normalized_two_mass(3.0, 0.01);
  delayed.hf.delay_s = 0.15;
  const VelocityLoop loop(delayed, PidGains{4.63, 0.64, 0.0, 0.0, 1.0, 0.0});
  ASSERT_TRUE(loop.stable());
  const PositionLoop p(functions_of(loop), std::nullopt);
  const ClosedLoopTransfer cl = loop.closed_loop();
  bool seen_unstable = false;
  for (double kpp : core::log_space(1e-3, 100.0, 41)) {
    const Polynomial chi = Polynomial{1.0, 0.0} * cl.characteristic + kpp * cl.motor_tracking.num();
    double max_re = -1e300;
    for (const std::complex<double>& z : chi.roots()) max_re = std::max(max_re, z.real());
    EXPECT_EQ(p.stable(kpp), max_re < 0.0) << "kpp " << kpp << " max Re " << max_re;
    seen_unstable = seen_unstable || max_re > 0.0;
  }
  EXPECT_TRUE(seen_unstable);
  // The robustly stable bound of the delay-free nominal lies inside the delayed loop's stability range
  // (RS covers the delay).
  const PositionLoop nominal(functions_of(e27_loop()), e27_weight());
  EXPECT_TRUE(p.stable(nominal.design().kpp_rs));
}

// ------------------------------------------------------------------------- eq. 7.110

/// E-fric plant (normalized table-5.1: a = 0.2, ζz = 0.06, r = 3, ζp = 0.15) with a placed PI.
struct FrictionCase {
  NormalizedPlant plant = normalized_two_mass(3.0, 0.06, 0.15, 0.2);
  PidGains gains;
  FrictionCase(double wp) {
    const PiGains g = pi_pole_placement(plant.motor(false), 0.6, 0.8).gains;
    gains = PidGains{g.kp, g.ki, 0.0, 0.0, wp, 0.0};
  }
};

TEST(PositionLoopClosedForm, Eq7110EqualsTheTransferFunctionAlgebra) {
  for (double wp : {1.0, 0.4}) {
    const FrictionCase c(wp);
    const VelocityLoop loop(c.plant, c.gains);
    ASSERT_TRUE(loop.has_load());
    const std::optional<FrictionTwoMass> m = physical_parameters_with_friction(c.plant);
    ASSERT_TRUE(m.has_value());
    for (double kpp : {0.05, 0.3, 2.0}) {
      SCOPED_TRACE("wp " + std::to_string(wp) + " kpp " + std::to_string(kpp));
      const PositionClosedLoop tf = position_closed_loop(loop.closed_loop(), kpp);
      const PositionClosedForm cf = position_closed_form(*m, c.gains, kpp);
      const PositionLoop freq(functions_of(loop), std::nullopt);
      for (double w : core::log_space(1e-3, 1e2, 37)) {
        EXPECT_LT(max_rel_diff(tf.load_tracking.frequency_response(w), cf.load_tracking.frequency_response(w)), 1e-10);
        EXPECT_LT(max_rel_diff(tf.load_from_load_torque.frequency_response(w),
                               cf.load_from_load_torque.frequency_response(w)), 1e-10);
        EXPECT_LT(max_rel_diff(freq.load_tracking(w, kpp), cf.load_tracking.frequency_response(w)), 1e-10);
        EXPECT_LT(max_rel_diff(freq.load_from_load_torque(w, kpp), cf.load_from_load_torque.frequency_response(w)), 1e-10);
      }
      // Σ a_i s^i is the cascade's characteristic polynomial (scaled by a5 = Il Im).
      const Polynomial a = cf.load_tracking.den();
      ASSERT_EQ(a.degree(), tf.characteristic.degree());
      for (int k = 0; k <= a.degree(); ++k) {
        const double expected = a.coefficient_of_power(k) / a.leading();
        const double got = tf.characteristic.coefficient_of_power(k) / tf.characteristic.leading();
        EXPECT_NEAR(got, expected, 1e-10 * std::max(1.0, std::abs(expected))) << "s^" << k;
      }
      // Unit DC gain of φl/φ* (integral action); φl/Tl(0) = −Ki Kpp/(Ki k Kpp) = −1/k.
      EXPECT_NEAR(cf.load_tracking.dc_gain(), 1.0, 1e-12);
      EXPECT_NEAR(cf.load_from_load_torque.dc_gain(), -1.0 / m->stiffness, 1e-12 / m->stiffness);
    }
  }
}

TEST(PositionLoopClosedForm, LoadDisturbanceDcGainIsTheShaftCompliance) {
  // φl/Tl(0) = −1/k: with integral action the motor holds its position and the load twists the shaft.
  const FrictionCase c(1.0);
  const VelocityLoop loop(c.plant, c.gains);
  const PositionLoop p(functions_of(loop), std::nullopt);
  const double k = physical_parameters_with_friction(c.plant)->stiffness;
  EXPECT_LT(std::abs(p.load_from_load_torque(1e-6, 0.5) + 1.0 / k), 1e-5 / k);
}

// ------------------------------------------------------------------------- API edges

TEST(PositionLoopApi, WithoutWeightOrLoadTheCorrespondingResultsAreZero) {
  const PositionLoop no_w2(functions_of(e27_loop()), std::nullopt);
  const PositionLoopDesign d = no_w2.design();
  EXPECT_GT(d.kpp_nominal, 0.0);
  EXPECT_EQ(d.kpp_rs, 0.0);
  EXPECT_EQ(d.kpp_rp, 0.0);
  EXPECT_EQ(d.kpp_rp_exact, 0.0);
  EXPECT_TRUE(std::isnan(no_w2.robust_stability_function(1.0, 1.0).real()));
  // A plant with a higher mode has no two-mass realization: no load side.
  NormalizedPlant multi = normalized_two_mass(3.0, 0.01);
  multi.higher_modes = {fit::Mode{{20.0, 0.01}, {24.0, 0.02}}};
  const VelocityLoop loop(multi, PidGains{4.63, 0.64, 0.0, 0.0, 1.0, 0.0});
  // (The E27 weight fails RS on this plant: ‖W2 T‖∞ = 1.52 from the second resonance; a weight
  // five times smaller passes.)
  const PositionLoop p(functions_of(loop), TransferFunction(Polynomial{0.5, 0.0}, Polynomial{1.0, 15.0}));
  EXPECT_FALSE(p.has_load());
  const PositionLoopDesign dm = p.design();
  EXPECT_EQ(dm.kpp_nominal, 0.0);
  EXPECT_GT(dm.kpp_rs, 0.0);
  EXPECT_TRUE(std::isnan(p.load_tracking(1.0, 1.0).real()));
}

TEST(PositionLoopApi, BadOptionsAndWeightsAreInputErrors) {
  PositionLoopOptions o;
  o.kpp_max = o.kpp_min;
  expect_input_error([&] { PositionLoop p(functions_of(e27_loop()), std::nullopt, o); }, "options.kpp_max", "kpp_min");
  o = {};
  o.omega_min = -1.0;
  expect_input_error([&] { PositionLoop p(functions_of(e27_loop()), std::nullopt, o); }, "options.omega_min", "> 0");
  expect_input_error(
      [&] { PositionLoop p(functions_of(e27_loop()), TransferFunction(Polynomial{1.0}, Polynomial{1.0, -2.0})); },
      "w2", "stable");
}

}  // namespace
}  // namespace servotwin::tuning
