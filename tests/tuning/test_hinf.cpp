// H-infinity mixed-sensitivity velocity design (C7.14). References: GNU Octave's control package in
// tests/data/core/hinf_reference.json (tools/reference/hinf_reference.m): the generalized plant
// built there from transfer-function objects (Octave's own realizations), its optimal gamma
// (bisection over hinfsyn SUBOPTIMAL = SLICOT SB10FD) and the central controller at a fixed gamma;
// and the mixed-sensitivity bound |S| <= gamma / |W1 V| that any solution must satisfy. The
// multi-mode (C7.16) and load-side (C7.17) variants are checked the same way against Octave, and
// against the findings their sections print.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <initializer_list>
#include <map>
#include <stdexcept>
#include <string>

#include "json_fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/hinf.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/tuning/hinf.hpp"
#include "servotwin/tuning/lqg.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace hinf_test {

const nlohmann::json& reference() {
  static const nlohmann::json j = test_support::read_json_fixture("core/hinf_reference.json", "hinf_reference.m");
  return j;
}

/// The fixture's case of this name (the test fails and stops when it is missing).
const nlohmann::json& case_named(const std::string& name) {
  for (const auto& c : reference()["cases"])
    if (c["name"] == name) return c;
  throw std::runtime_error("hinf_reference.json has no case " + name);
}

struct VelocityCase {
  std::string name;
  NormalizedPlant plant;
  VelocityHinfWeights weights;
  core::StateSpace octave_plant;
  double gamma_optimal = 0.0, gamma_suboptimal = 0.0;
  nlohmann::json raw;
};

std::vector<VelocityCase> velocity_cases() {
  std::vector<VelocityCase> out;
  for (const auto& c : reference()["cases"]) {
    if (c["name"].get<std::string>().rfind("velocity", 0) != 0) continue;
    const auto& w = c["weights"];
    VelocityCase v;
    v.name = c["name"].get<std::string>();
    v.plant = normalized_two_mass(w["r"].get<double>(), w["zz"].get<double>(), w["zp"].get<double>(), w["a"].get<double>());
    v.weights.omega_0s = w["w0S"].get<double>();
    v.weights.omega_0t = w["w0T"].get<double>();
    v.weights.xi_v = w["xv"].get<double>();
    v.weights.ms = w["Ms"].get<double>();
    v.weights.mt = w["Mt"].get<double>();
    const auto n = c["states"].get<Eigen::Index>();
    v.octave_plant = {test_support::octave_matrix(c["A"], n, n), test_support::octave_matrix(c["B"], n, 2),
                      test_support::octave_matrix(c["C"], 3, n), test_support::octave_matrix(c["D"], 3, 2)};
    v.gamma_optimal = c["gamma_optimal"].get<double>();
    v.gamma_suboptimal = c["gamma_suboptimal"].get<double>();
    v.raw = c;
    out.push_back(v);
  }
  return out;
}

TEST(VelocityHinf, GeneralizedPlantEqualsOctavesConstruction) {
  const auto cases = velocity_cases();
  ASSERT_EQ(cases.size(), 3u);
  for (const VelocityCase& c : cases) {
    SCOPED_TRACE(c.name);
    const core::StateSpace p = velocity_mixed_sensitivity_plant(c.plant, c.weights);
    ASSERT_EQ(p.states(), 8);
    for (const double w : {0.01, 0.1, 0.5, 1.0, 1.9, 2.0, 4.0, 10.0, 100.0}) {
      const Eigen::MatrixXcd expected = core::frequency_response(c.octave_plant, w);
      const Eigen::MatrixXcd got = core::frequency_response(p, w);
      EXPECT_LT((got - expected).norm(), 1e-9 * expected.norm()) << "omega " << w;
    }
  }
}

TEST(VelocityHinf, OptimalGammaAndControllerMatchOctave) {
  for (const VelocityCase& c : velocity_cases()) {
    SCOPED_TRACE(c.name);
    const HinfDesign d = velocity_hinf(c.plant, c.weights);
    // Tolerance 1e-4 of the synthesis; ours may lie a little below SLICOT's (core test_hinf).
    EXPECT_LE(d.gamma_optimal, c.gamma_optimal * (1.0 + 1.1e-4));
    EXPECT_GE(d.gamma_optimal, c.gamma_optimal * (1.0 - 1e-4));
    EXPECT_NEAR(d.gamma, 1.01 * d.gamma_optimal, 1e-12);
    EXPECT_LT(d.closed_loop_norm, d.gamma * (1.0 + 1e-6));

    // At Octave's fixed gamma the central controller K0 is Octave's.
    VelocityHinfWeights at_fixed = c.weights;
    const auto k0 = core::hinf_central_controller(velocity_mixed_sensitivity_plant(c.plant, at_fixed), 1, 1,
                                                  c.gamma_suboptimal);
    ASSERT_TRUE(k0.has_value());
    const auto& omega = c.raw["omega"];
    for (std::size_t i = 0; i < omega.size(); ++i) {
      const std::complex<double> expected(c.raw["K_re"][i].get<double>(), c.raw["K_im"][i].get<double>());
      EXPECT_LT(std::abs(core::frequency_response(k0->controller, omega[i].get<double>(), 0, 0) - expected),
                1e-6 * std::abs(expected));
    }
  }
}

// The defining property of the design: |W1 S V| <= gamma at every frequency (the first row of the
// closed loop), i.e. |S| <= gamma Ms / |V|; checked on the loop the tuner analyses (the compensator
// K0/s in its 2-DoF form), so the integrator and the input convention are covered too.
TEST(VelocityHinf, SensitivityRespectsTheMixedSensitivityBound) {
  for (const VelocityCase& c : velocity_cases()) {
    SCOPED_TRACE(c.name);
    const HinfDesign d = velocity_hinf(c.plant, c.weights);
    const VelocityLoop loop(c.plant, two_dof_form(d.compensator), false);
    ASSERT_TRUE(loop.stable());
    const double r = c.plant.r;
    const double w0s = c.weights.omega_0s, xv = c.weights.xi_v;
    for (const double w : core::log_space(1e-2, 1e2, 61)) {
      const std::complex<double> s(0.0, w);
      const std::complex<double> target = (s + w0s) * (s + w0s) * (s * s + 2.0 * xv * r * s + r * r);
      const std::complex<double> den =
          s * (s + c.plant.a) * (s * s + 2.0 * c.plant.zeta_p * r * s + r * r);
      const double bound = d.gamma * c.weights.ms * std::abs(den) / std::abs(target);
      EXPECT_LE(std::abs(loop.sensitivity(w)), bound * (1.0 + 1e-6)) << "omega " << w;
    }
    EXPECT_TRUE(std::abs(d.controller_poles.front()) < 1e-9 * std::abs(d.controller_poles.back()))
        << "K = K0/s has its integrator";
  }
}

// The position design (C7.14's position weights, Pe = Pm/s^2): the generalized plant equals
// Octave's construction, gamma and K0 match hinfsyn, and the loop it closes on the position plant
// Pm/s respects |S| <= gamma Ms |den(Pe)| / |(s + w0S)^3 (s^2 + 2 xi_v r s + r^2)|.
TEST(PositionHinf, MatchesOctaveAndRespectsTheMixedSensitivityBound) {
  const nlohmann::json& c = case_named("position_r3");
  const auto& w = c["weights"];
  const NormalizedPlant plant =
      normalized_two_mass(w["r"].get<double>(), w["zz"].get<double>(), w["zp"].get<double>(), w["a"].get<double>());
  VelocityHinfWeights weights;
  weights.omega_0s = w["w0S"].get<double>();
  weights.omega_0t = w["w0T"].get<double>();
  weights.xi_v = w["xv"].get<double>();
  const auto n = c["states"].get<Eigen::Index>();
  const core::StateSpace octave = {test_support::octave_matrix(c["A"], n, n), test_support::octave_matrix(c["B"], n, 2),
                                   test_support::octave_matrix(c["C"], 3, n), test_support::octave_matrix(c["D"], 3, 2)};
  const core::StateSpace p = position_mixed_sensitivity_plant(plant, weights);
  ASSERT_EQ(p.states(), 10);
  for (const double f : {0.01, 0.3, 1.0, 3.0, 30.0}) {
    const Eigen::MatrixXcd expected = core::frequency_response(octave, f);
    EXPECT_LT((core::frequency_response(p, f) - expected).norm(), 1e-9 * expected.norm()) << "omega " << f;
  }
  const HinfDesign d = position_hinf(plant, weights);
  const double gamma_octave = c["gamma_optimal"].get<double>();
  // Ours lies below SLICOT's here (6e-4): SB10FD gives up earlier near the optimum; ours is met by
  // its controller's closed loop (closed_loop_norm, checked against gamma).
  EXPECT_LE(d.gamma_optimal, gamma_octave * (1.0 + 2e-4));
  EXPECT_GE(d.gamma_optimal, gamma_octave * (1.0 - 1e-3));
  EXPECT_LT(d.closed_loop_norm, d.gamma * (1.0 + 1e-6));
  const auto k0 = core::hinf_central_controller(p, 1, 1, c["gamma_suboptimal"].get<double>());
  ASSERT_TRUE(k0.has_value());
  for (std::size_t i = 0; i < c["omega"].size(); ++i) {
    const std::complex<double> expected(c["K_re"][i].get<double>(), c["K_im"][i].get<double>());
    EXPECT_LT(std::abs(core::frequency_response(k0->controller, c["omega"][i].get<double>(), 0, 0) - expected),
              1e-6 * std::abs(expected));
  }
  const double r = plant.r, w0s = weights.omega_0s, xv = weights.xi_v;
  const core::TransferFunction motor = plant.motor(false);
  for (const double f : core::log_space(1e-2, 1e2, 61)) {
    const std::complex<double> s(0.0, f);
    const std::complex<double> loop = motor(s) / s * core::frequency_response(d.compensator, f, 0, 1) * -1.0;
    const std::complex<double> sensitivity = 1.0 / (1.0 + loop);
    const std::complex<double> den = s * s * (s + plant.a) * (s * s + 2.0 * plant.zeta_p * r * s + r * r);
    const std::complex<double> target = std::pow(s + w0s, 3) * (s * s + 2.0 * xv * r * s + r * r);
    EXPECT_LE(std::abs(sensitivity), d.gamma * weights.ms * std::abs(den) / std::abs(target) * (1.0 + 1e-6))
        << "omega " << f;
  }
}

TEST(VelocityHinf, RollOffIsTheDesignWithTheFilterAsAKnownLagAndTheFilterInSeries) {
  // The roll-off F = wf/(s + wf) is designed with as a lag of the torque path. Reference: the same
  // synthesis on the plant given a current lag tau = 1/wf (the HF-dynamics route, checked against
  // Octave above) yields K'; the roll-off design must be F K' (and the same gamma), strictly proper.
  const double wf = 20.0;
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  NormalizedPlant lagged = plant;
  lagged.hf.current_lag_s = 1.0 / wf;
  VelocityHinfWeights w;
  w.omega_0s = 0.6;
  const HinfDesign reference = velocity_hinf(lagged, w);
  w.rolloff = wf;
  const HinfDesign d = velocity_hinf(plant, w);
  EXPECT_NEAR(d.gamma_optimal, reference.gamma_optimal, 1e-9 * reference.gamma_optimal);
  EXPECT_EQ(d.compensator.states(), reference.compensator.states() + 1);
  EXPECT_EQ(d.full_order, reference.full_order + 1);
  EXPECT_EQ(d.compensator.D.norm(), 0.0);  // strictly proper
  for (const double x : {0.01, 0.3, 1.0, 3.0, 30.0, 300.0}) {
    const std::complex<double> f = wf / std::complex<double>(wf, x);
    for (Eigen::Index k = 0; k < 2; ++k) {
      const std::complex<double> got = core::frequency_response(d.compensator, x, 0, k);
      const std::complex<double> want = f * core::frequency_response(reference.compensator, x, 0, k);
      EXPECT_LT(std::abs(got - want), 1e-6 * std::abs(want)) << x << " input " << k;
    }
  }
  // Above wf the gain falls 20 dB per decade more than the biproper K' (which levels off).
  const double ratio = std::abs(core::frequency_response(d.compensator, 1e4, 0, 1)) /
                       std::abs(core::frequency_response(reference.compensator, 1e4, 0, 1));
  EXPECT_NEAR(ratio, wf / 1e4, 1e-3 * wf / 1e4);
}

TEST(VelocityHinf, RejectsWeightsOutOfRange) {
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const auto field_of = [&](VelocityHinfWeights w) {
    try {
      (void)velocity_hinf(plant, w);
    } catch (const core::InputError& e) {
      return e.where().field;
    }
    return std::string("no error");
  };
  VelocityHinfWeights w;
  w.xi_v = 0.5;
  EXPECT_EQ(field_of(w), "xi_v");
  w = {};
  w.rolloff = 0.0;
  EXPECT_EQ(field_of(w), "rolloff");
  w = {};
  w.omega_0s = 0.0;
  EXPECT_EQ(field_of(w), "omega_0s");
  w = {};
  w.omega_0t = -1.0;
  EXPECT_EQ(field_of(w), "omega_0t");
  w = {};
  w.ms = std::nan("");
  EXPECT_EQ(field_of(w), "ms");
  w = {};
  w.backoff = 0.5;
  EXPECT_EQ(field_of(w), "backoff");
}

// ------------------------------------------------------------------------ C7.16 multiple modes

/// The demo plant of catalog C7.16 (eq. 7.165): wz1 = 1, xi_z1 = 0.01, w1 = 4, xi_1 = 0.04,
/// wz2 = 6, xi_z2 = 0.01, w2 = 12, xi_2 = 0.02.
NormalizedPlant two_mode_plant() {
  NormalizedPlant p = normalized_two_mass(4.0, 0.01, 0.04);
  p.higher_modes.push_back(fit::Mode{{6.0, 0.01}, {12.0, 0.02}});
  return p;
}

struct ModeCase {
  ModeHandling modes;
  const nlohmann::json* raw;
};

std::vector<ModeCase> mode_cases() {
  std::vector<ModeCase> out;
  for (const auto& c : reference()["cases"]) {
    if (c["name"] == "two_modes_passive") out.push_back({ModeHandling::kPassive, &c});
    if (c["name"] == "two_modes_active") out.push_back({ModeHandling::kActive, &c});
  }
  return out;
}

VelocityHinfWeights weights_of(const nlohmann::json& c, ModeHandling modes) {
  const auto& w = c["weights"];
  VelocityHinfWeights v;
  v.omega_0s = w["w0S"].get<double>();
  v.omega_0t = w["w0T"].get<double>();
  v.xi_v = w["xv"].get<double>();
  v.ms = w["Ms"].get<double>();
  v.mt = w["Mt"].get<double>();
  v.modes = modes;
  return v;
}

/// A design of the fixture's case `c` against Octave: our generalized plant `p` equals Octave's
/// (1e-9 at `omegas`), the optimal gamma agrees to 1e-4 and the central controller at Octave's
/// fixed gamma is its controller (1e-6).
void expect_octave_design(const nlohmann::json& c, const core::StateSpace& p, const HinfDesign& d,
                          std::initializer_list<double> omegas) {
  const auto n = c["states"].get<Eigen::Index>();
  const core::StateSpace octave{test_support::octave_matrix(c["A"], n, n), test_support::octave_matrix(c["B"], n, 2),
                                test_support::octave_matrix(c["C"], 3, n), test_support::octave_matrix(c["D"], 3, 2)};
  for (const double omega : omegas) {
    const Eigen::MatrixXcd expected = core::frequency_response(octave, omega);
    EXPECT_LT((core::frequency_response(p, omega) - expected).norm(), 1e-9 * expected.norm()) << "omega " << omega;
  }
  EXPECT_LE(d.gamma_optimal, c["gamma_optimal"].get<double>() * (1.0 + 1.1e-4));
  EXPECT_GE(d.gamma_optimal, c["gamma_optimal"].get<double>() * (1.0 - 1e-4));
  const auto k0 = core::hinf_central_controller(p, 1, 1, c["gamma_suboptimal"].get<double>());
  ASSERT_TRUE(k0.has_value());
  const auto& omega = c["omega"];
  for (std::size_t i = 0; i < omega.size(); ++i) {
    const std::complex<double> expected(c["K_re"][i].get<double>(), c["K_im"][i].get<double>());
    EXPECT_LT(std::abs(core::frequency_response(k0->controller, omega[i].get<double>(), 0, 0) - expected),
              1e-6 * std::abs(expected));
  }
}

TEST(MultiModeHinf, GeneralizedPlantGammaAndControllerMatchOctave) {
  const auto cases = mode_cases();
  ASSERT_EQ(cases.size(), 2u);
  const NormalizedPlant plant = two_mode_plant();
  for (const ModeCase& m : cases) {
    const nlohmann::json& c = *m.raw;
    SCOPED_TRACE(c["name"].get<std::string>());
    const VelocityHinfWeights w = weights_of(c, m.modes);
    const core::StateSpace p = velocity_mixed_sensitivity_plant(plant, w);
    ASSERT_EQ(p.states(), 10);  // 8 of one mode + 2 for mode 2
    expect_octave_design(c, p, velocity_hinf(plant, w), {0.01, 0.5, 1.0, 4.0, 6.0, 11.9, 12.0, 12.1, 100.0});
  }
}

/// The smallest damping among the closed-loop poles near `omega` (within 15 %).
double damping_near(const std::vector<std::complex<double>>& poles, double omega) {
  double out = 1.0;
  for (const auto& p : poles)
    if (std::abs(std::abs(p) - omega) < 0.15 * omega) out = std::min(out, -p.real() / std::abs(p));
  return out;
}

/// The loop of a design on the full plant (the higher modes in, no HF dynamics).
VelocityLoop full_plant_loop(const NormalizedPlant& plant, const HinfDesign& d) {
  return VelocityLoop(plant, two_dof_form(d.compensator), false, true);
}

/// max |Pm S| (motor torque disturbance -> motor velocity) for omega in [lo, hi].
double motor_disturbance_peak(const VelocityLoop& loop, double lo, double hi) {
  double peak = 0.0;
  for (double omega = lo; omega <= hi; omega += 0.005) peak = std::max(peak, std::abs(loop.plant(omega) * loop.sensitivity(omega)));
  return peak;
}

TEST(MultiModeHinf, PassiveCancelsTheSecondModeActiveDampsIt) {
  // C7.16's findings on its demo plant (Sec. 7.4, Figs. 7.36-7.37), at w0S = 1, w0T = r:
  // - the first-mode design at these weights spills over: unstable with mode 2;
  // - the passive design cancels mode 2: the pair keeps its open-loop damping 0.02 in the closed
  //   loop, K has a notch at w2 and motor-side disturbances ring there;
  // - the active design relocates it to xi_v (V's numerator) at a larger controller gain at w2.
  const NormalizedPlant plant = two_mode_plant();
  VelocityHinfWeights w;
  w.omega_0s = 1.0;
  w.omega_0t = 4.0;
  EXPECT_FALSE(full_plant_loop(plant, velocity_hinf(plant, w)).stable());

  w.modes = ModeHandling::kPassive;
  const VelocityLoop passive = full_plant_loop(plant, velocity_hinf(plant, w));
  w.modes = ModeHandling::kActive;
  const VelocityLoop active = full_plant_loop(plant, velocity_hinf(plant, w));
  ASSERT_TRUE(passive.stable());
  ASSERT_TRUE(active.stable());
  EXPECT_NEAR(damping_near(passive.closed_loop().characteristic.roots(), 12.0), 0.02, 1e-3);
  EXPECT_NEAR(damping_near(active.closed_loop().characteristic.roots(), 12.0), w.xi_v, 1e-3);
  EXPECT_LT(std::abs(passive.controller(12.0)), 0.1 * std::abs(active.controller(12.0)));
  EXPECT_GT(motor_disturbance_peak(passive, 9.0, 15.0), 10.0 * motor_disturbance_peak(active, 9.0, 15.0));
  // Both damp mode 1 actively: no closed-loop pole near r below 0.7 (the passive design's
  // partial placement there is approximate: 0.77 for the target 0.8).
  EXPECT_GT(damping_near(passive.closed_loop().characteristic.roots(), 4.0), 0.7);
  EXPECT_GT(damping_near(active.closed_loop().characteristic.roots(), 4.0), 0.7);
}

TEST(MultiModeHinf, ControllerOrdersAndBalancedTruncation) {
  // Orders of C7.14/C7.16: the velocity controller of one mode has 5 states, each higher mode adds
  // 2 (7 for the demo plant); the full order (generalized plant + integrator) carries W2's 4 poles,
  // which K cancels (Hankel values near rounding level, dropped by default).
  const NormalizedPlant plant = two_mode_plant();
  VelocityHinfWeights w;
  w.omega_0s = 1.0;
  w.omega_0t = 4.0;
  NormalizedPlant one_mode = plant;
  one_mode.higher_modes.clear();
  const HinfDesign single = velocity_hinf(one_mode, w);
  EXPECT_EQ(single.full_order, 9);
  EXPECT_EQ(single.compensator.states(), 5);
  for (ModeHandling m : {ModeHandling::kPassive, ModeHandling::kActive}) {
    SCOPED_TRACE(to_string(m));
    w.modes = m;
    w.controller_order.reset();
    const HinfDesign minimal = velocity_hinf(plant, w);
    EXPECT_EQ(minimal.full_order, 11);
    EXPECT_EQ(minimal.compensator.states(), 7);
    EXPECT_LT(minimal.reduction_error_bound, 1e-5 * minimal.hankel.front());
    // The minimal realization has K's response (series K0 * 1/s, evaluated independently).
    for (const double omega : {0.1, 1.0, 4.0, 12.0, 50.0}) {
      const std::complex<double> k0 = core::frequency_response(minimal.k0, omega, 0, 0) / std::complex<double>(0.0, omega);
      EXPECT_LT(std::abs(core::frequency_response(minimal.compensator, omega, 0, 0) - k0), 1e-5 * std::abs(k0)) << omega;
    }
  }
  // A real truncation: the active design's stable part (Hankel values 19.8, 18.9, 2.37, 0.646, ...)
  // cut to 3 of its states (6 in all, with the integrator and the unstable pair): K moves by no
  // more than Glover's bound 2 (0.646) at any frequency; this loop stays stable (order 5 would not).
  w.modes = ModeHandling::kActive;
  const HinfDesign full = velocity_hinf(plant, w);
  w.controller_order = 6;
  const HinfDesign reduced = velocity_hinf(plant, w);
  EXPECT_EQ(reduced.compensator.states(), 6);
  EXPECT_NEAR(reduced.reduction_error_bound, 2.0 * reduced.hankel[3], 1e-3 * reduced.hankel[3]);
  double worst = 0.0;
  for (double omega = 0.01; omega < 1000.0; omega *= 1.02) {
    worst = std::max(worst, std::abs(core::frequency_response(full.compensator, omega, 0, 0) -
                                     core::frequency_response(reduced.compensator, omega, 0, 0)));
  }
  EXPECT_GE(worst, reduced.hankel[3] * (1.0 - 1e-3));  // and at least the first discarded value
  EXPECT_LE(worst, reduced.reduction_error_bound * (1.0 + 1e-6));
  EXPECT_TRUE(full_plant_loop(plant, reduced).stable());
  // The passive design keeps 5 unstable states (integrator, two real poles, one pair): 4 is refused.
  w.modes = ModeHandling::kPassive;
  w.controller_order = 4;
  try {
    (void)velocity_hinf(plant, w);
    ADD_FAILURE() << "order 4 accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "controller_order");
  }
}

// ------------------------------------------------------------------ C7.17 load-side feedback

TEST(LoadSideHinf, GeneralizedPlantGammaAndControllerMatchOctave) {
  const nlohmann::json& c = case_named("load_side_r3");
  const auto& w = c["weights"];
  const NormalizedPlant plant = normalized_two_mass(w["r"].get<double>(), w["zz"].get<double>());
  VelocityHinfWeights weights = weights_of(c, ModeHandling::kFirstMode);
  const core::StateSpace p = load_side_mixed_sensitivity_plant(plant, weights);
  ASSERT_EQ(p.states(), 8);
  expect_octave_design(c, p, load_side_hinf(plant, weights), {0.01, 0.5, 1.0, 2.9, 3.0, 10.0, 100.0});
}

/// The load-side loop of a design: K (first input of the compensator) on Pl = plant.load().
struct LoadLoop {
  double peak_s = 0.0, peak_t = 0.0, bandwidth = 0.0, hf_gain = 0.0;
  bool stable = false;
};

LoadLoop load_loop(const NormalizedPlant& plant, const HinfDesign& d) {
  const core::TransferFunction pl = *plant.load();
  core::StateSpace k = d.compensator;  // column 0: u = K (w* - wl)
  k.B = d.compensator.B.col(0);
  k.D = d.compensator.D.col(0);
  const core::StateSpace open = core::series(k, core::to_state_space(pl));
  const core::StateSpace unity{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Ones(1, 1)};
  const core::StateSpace closed = core::feedback(open, unity);
  LoadLoop out;
  out.stable = true;
  for (const auto& p : Eigen::VectorXcd(closed.A.eigenvalues())) out.stable = out.stable && p.real() < 0.0;
  for (double omega = 1e-3; omega < 1e3; omega *= 1.01) {
    const std::complex<double> l = core::frequency_response(k, omega, 0, 0) * pl.frequency_response(omega);
    const double t = std::abs(l / (1.0 + l));
    out.peak_s = std::max(out.peak_s, std::abs(1.0 / (1.0 + l)));
    out.peak_t = std::max(out.peak_t, t);
    if (out.bandwidth == 0.0 && t < std::sqrt(0.5)) out.bandwidth = omega;
  }
  out.hf_gain = std::abs(core::frequency_response(k, 100.0, 0, 0));
  return out;
}

TEST(LoadSideHinf, C717DemoMeetsThePeakLimitsAndPaysInControllerGain) {
  // C7.17's demo: w0S in {1, 2, 5, 10} rad/s (normalized: omega_z = 1), w0T raised from r until
  // ||S||, ||Tl|| <= 1.8. Every w0S finds such a w0T, and the HF controller gain it takes grows
  // steeply past the resonance ("a bandwidth >> wn needs a huge HF controller gain").
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  VelocityHinfWeights w;
  w.ms = 1.8;
  w.mt = 1.8;
  std::map<double, LoadLoop> met;
  for (const double w0s : {1.0, 2.0, 5.0, 10.0}) {
    w.omega_0s = w0s;
    for (int step = 0; step < 5 && !met.count(w0s); ++step) {
      w.omega_0t = std::max(plant.r, w0s) * std::ldexp(1.0, step);
      const LoadLoop l = load_loop(plant, load_side_hinf(plant, w));
      if (l.stable && l.peak_s <= w.ms && l.peak_t <= w.mt) met[w0s] = l;
    }
    ASSERT_TRUE(met.count(w0s)) << "no w0T meets the limits at w0S = " << w0s;
  }
  // Measured: |K(j100)| = 28 (w0S = 1, w0T = 12), 17 (2, 6), 142 (5, 10), 1510 (10, 20).
  EXPECT_GT(met[10.0].hf_gain, 50.0 * met[1.0].hf_gain);
  EXPECT_GT(met[5.0].hf_gain, 3.0 * met[1.0].hf_gain);
  // A modal model has no load to measure.
  try {
    (void)load_side_hinf(two_mode_plant(), w);
    ADD_FAILURE() << "a two-mode plant accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "plant");
  }
}

}  // namespace hinf_test
}  // namespace
}  // namespace servotwin::tuning
