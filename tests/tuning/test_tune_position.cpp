// The tuner's full-order position controllers, lqg-pos and hinf-pos (C7.13, C7.14): the position
// LQG and H-infinity designs with C7.13's reference prefilter, judged on positions.
// References: scipy's regulator and Kalman-filter poles of the C7.13 demo (tools/reference/
// tuning_lqg_reference.py, "position" case r = 3, zeta_z = 0.01, kbw = 1), to which the
// prefilter's pole -1/tau adds (separation principle); the closed loop of plant and compensator
// written out in state space (test::position_closed_loop_ss), independently of the
// transfer-function route (velocity form) the tuner analyses, for the prefilter's no-overshoot
// boundary, the bandwidth, the step overshoot and the static twist; a brute-force kbw scan
// evaluated here with its own spec code for the automatic search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "fixture.hpp"
#include "json_fixture.hpp"
#include "servotwin/core/norms.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/tuning/compare.hpp"
#include "servotwin/tuning/hinf.hpp"
#include "servotwin/tuning/lqg.hpp"
#include "servotwin/tuning/tune.hpp"

namespace servotwin::tuning {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace tune_position_test {

using Complex = std::complex<double>;

const nlohmann::json& lqg_reference() {
  static const nlohmann::json j = test_support::read_json_fixture("tuning/lqg_reference.json", "tuning_lqg_reference.py");
  return j;
}

std::vector<Complex> roots_of(const nlohmann::json& pairs) {
  std::vector<Complex> out;
  for (const auto& p : pairs) out.push_back(test::root_of(p));
  return out;
}

TuneOptions position_options(Structure structure) {
  TuneOptions o;
  o.structure = structure;
  return o;
}

/// The normalized closed loop of plant and compensator in state space: inputs [φ*, Tl], outputs
/// [φm, φl].
core::StateSpace closed_loop(const NormalizedPlant& plant, const core::StateSpace& compensator) {
  const FrictionTwoMass m = *two_mass_realization(plant);
  return test::position_closed_loop_ss(two_mass_state_space(m, true), compensator);
}

/// Overshoot of the load position's unit step, simulated from the state space (ZOH at dt).
double load_step_overshoot(const core::StateSpace& cl, double dt, std::size_t samples) {
  core::StateSpace from_reference{cl.A, cl.B.col(0), cl.C.row(1), cl.D.block(1, 0, 1, 1)};
  core::DiscreteSimulator sim(core::discretize_zoh(from_reference, dt));
  double peak = 0.0;
  for (std::size_t k = 0; k < samples; ++k) peak = std::max(peak, sim.step(1.0));
  return std::max(0.0, peak - 1.0);
}

TEST(TunePosition, LqgPosAtTheDemoKbwHasScipysPolesAndItsPrefilterAtTheOvershootBoundary) {
  const nlohmann::json& ref = lqg_reference().at("position").at(0);
  ASSERT_EQ(ref.at("r").get<double>(), 3.0);
  ASSERT_EQ(ref.at("bm").get<double>(), 0.0);
  TuneOptions o = position_options(Structure::kLqgPos);
  o.kbw = ref.at("kbw").get<double>();
  const TuneResult result = tune(test::two_mass_model(3.0, ref.at("zeta_z").get<double>()), o);
  const Controller& c = result.controller;
  ASSERT_TRUE(c.full_order && c.full_order->position_weights);
  EXPECT_EQ(c.full_order->position_weights->measurement_noise, 0.01);  // C7.13's V, not raised for a given kbw
  const double tau = c.full_order->prefilter_tau;
  ASSERT_GT(tau, 0.0);
  EXPECT_EQ(c.full_order->compensator.states(), 7);  // C7.13: order 6 + prefilter

  // Separation: the loop's poles are the regulator's, the estimator's and the prefilter's.
  std::vector<Complex> expected = roots_of(ref.at("lqr_poles"));
  for (const Complex& p : roots_of(ref.at("kf_poles"))) expected.push_back(p);
  expected.emplace_back(-1.0 / tau, 0.0);
  const std::vector<Complex> got = test::sorted_roots(c.predicted.closed_loop_poles), want = test::sorted_roots(expected);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_LT(std::abs(got[i] - want[i]), 1e-5 * std::abs(want[i])) << i;

  // The state-space route: φl/φ* peaks at exactly 1 (the prefilter's boundary), is 1 at DC and
  // −3 dB at the predicted bandwidth; the predicted indices are positions.
  const core::StateSpace cl = closed_loop(result.plant, c.full_order->compensator);
  const auto load = [&](double w) { return core::frequency_response(cl, w, 1, 0); };
  const std::vector<double> grid = core::log_space(1e-3, 1e2, 4000);
  EXPECT_NEAR(core::peak_on_grid(load, grid, 1e-10).value, 1.0, 1e-6);
  EXPECT_NEAR(c.predicted.peak_tl, 1.0, 1e-6);
  EXPECT_NEAR(std::abs(load(1e-5)), 1.0, 1e-6);
  EXPECT_NEAR(std::abs(load(c.predicted.bandwidth_load)), std::pow(10.0, -3.0 / 20.0), 1e-6);
  // The step: overshoot of the simulated state space against the analysis' (both exact ZOH).
  EXPECT_NEAR(load_step_overshoot(cl, c.predicted.sample_time, 20000), c.predicted.overshoot, 1e-4);
}

/// The automatic search's spec, evaluated here on its own: stable, ‖S‖∞ <= Ms and the unfiltered
/// ‖φl/φ*‖∞ <= Mt on a dense grid; the bandwidth of φl/φ* through the smallest no-overshoot
/// prefilter. 0 for an infeasible design.
double brute_force_bandwidth(const NormalizedPlant& plant, const core::StateSpace& compensator, const TuneOptions& o) {
  const VelocityLoop loop(plant, velocity_form(two_dof_form(compensator)));
  if (!loop.stable()) return 0.0;
  const std::vector<double> grid = core::log_space(1e-3, 1e2, 3000);
  const auto tracking = [&](double w) { return w == 0.0 ? Complex(1.0, 0.0) : loop.load_tracking(w) / Complex(0.0, w); };
  if (core::peak_on_grid([&](double w) { return loop.sensitivity(w); }, grid, 1e-6).value > o.ms) return 0.0;
  if (core::peak_on_grid(tracking, grid, 1e-6).value > o.mt) return 0.0;
  const double tau = prefilter_time_constant(tracking, grid, 1.0, 1e-6);
  std::vector<double> from_zero{0.0};
  from_zero.insert(from_zero.end(), grid.begin(), grid.end());
  return core::bandwidth([&](double w) { return tracking(w) / (tau * Complex(0.0, w) + 1.0); }, from_zero).value_or(0.0);
}

TEST(TunePosition, AutomaticLqgPosHasTheLargestFilteredBandwidthOfABruteForceScan) {
  const TuneOptions o = position_options(Structure::kLqgPos);
  const TuneResult result = tune(test::two_mass_model(3.0, 0.01), o);
  const Controller& c = result.controller;
  ASSERT_TRUE(c.full_order && c.full_order->position_weights);
  const PositionLqgOptions chosen = *c.full_order->position_weights;
  const FrictionTwoMass m = *two_mass_realization(result.plant);
  // The compensator is C7.13's design at the chosen kbw with its prefilter in front.
  const core::StateSpace expected = with_prefilter(position_lqg(m, 3.0, chosen).compensator, c.full_order->prefilter_tau);
  for (const double w : {0.05, 0.5, 2.0})
    EXPECT_LT((core::frequency_response(c.full_order->compensator, w) - core::frequency_response(expected, w)).norm(),
              1e-9 * core::frequency_response(expected, w).norm());
  const double best = brute_force_bandwidth(result.plant, position_lqg(m, 3.0, chosen).compensator, o);
  ASSERT_GT(best, 0.0);  // the tuner's choice meets the spec as evaluated here
  EXPECT_NEAR(c.predicted.bandwidth_load, best, 1e-3 * best);
  for (const double kbw : core::log_space(1e-4, 1e3, 43)) {
    PositionLqgOptions w = chosen;
    w.kbw = kbw;
    EXPECT_LE(brute_force_bandwidth(result.plant, position_lqg(m, 3.0, w).compensator, o), best * 1.01) << kbw;
  }
}

TEST(TunePosition, HinfPosIsTheC714PositionDesignWithItsPrefilterWithinTheSpec) {
  const TuneOptions o = position_options(Structure::kHinfPos);
  const TuneResult result = tune(test::two_mass_model(3.0, 0.01), o);
  const Controller& c = result.controller;
  ASSERT_TRUE(c.full_order && c.full_order->hinf);
  const HinfSummary& h = *c.full_order->hinf;
  VelocityHinfWeights w;
  w.omega_0s = h.omega_0s;
  w.omega_0t = h.omega_0t;
  w.xi_v = h.xi_v;
  w.ms = o.ms;
  w.mt = o.mt;
  const core::StateSpace expected = with_prefilter(position_hinf(result.plant, w).compensator, c.full_order->prefilter_tau);
  for (const double x : {0.05, 0.5, 2.0})
    EXPECT_LT((core::frequency_response(c.full_order->compensator, x) - core::frequency_response(expected, x)).norm(),
              1e-6 * core::frequency_response(expected, x).norm());
  EXPECT_GT(brute_force_bandwidth(result.plant, position_hinf(result.plant, w).compensator, o), 0.0);
  // Judged on positions through the state-space route: no overshoot in frequency, integral
  // action (φl → φ*), and under a load torque the motor held at φ* with the load at the static
  // twist −Tl/k (normalized k = r² − 1 = 8).
  const core::StateSpace cl = closed_loop(result.plant, c.full_order->compensator);
  const std::vector<double> grid = core::log_space(1e-3, 1e2, 3000);
  EXPECT_LE(core::peak_on_grid([&](double x) { return core::frequency_response(cl, x, 1, 0); }, grid, 1e-10).value,
            1.0 + 1e-6);
  EXPECT_NEAR(std::abs(core::frequency_response(cl, 1e-6, 1, 0)), 1.0, 1e-6);
  EXPECT_NEAR(std::abs(core::frequency_response(cl, 1e-6, 0, 1)), 0.0, 1e-4);
  EXPECT_NEAR(core::frequency_response(cl, 1e-6, 1, 1).real(), -1.0 / 8.0, 1e-4);
  EXPECT_LE(c.predicted.peak_s, o.ms * (1.0 + 1e-3));
  EXPECT_LE(c.predicted.peak_tl, 1.0 + 1e-6);
}

/// A load-measuring structure is refused on `model` with a second mode (no two-mass load to
/// measure: the error names --structure and says `message`) and by the motor-feedback comparison.
void expect_refused_without_a_two_mass_load(const fit::PlantModel& model, Structure structure,
                                            const std::string& message) {
  fit::PlantModel two_modes = model;
  two_modes.modes.push_back({{8.0 * 2.0 * std::numbers::pi * 40.0, 0.01}, {10.0 * 2.0 * std::numbers::pi * 40.0, 0.02}});
  test::expect_input_error([&] { (void)tune(two_modes, position_options(structure)); }, "--structure", message);
  test::expect_input_error([&] { (void)compare_structures(model, TuneOptions{}, {structure}); }, "structures",
                           "measures the load");
}

TEST(TunePosition, PositionStructuresAreRefusedWhereAVelocityLoopIsExpected) {
  test::expect_input_error(
      [] { (void)compare_structures(test::two_mass_model(3.0, 0.01), TuneOptions{}, {Structure::kLqgPos}); },
      "structures", "closes the position loop");
  EXPECT_EQ(structure_from_string("hinf-pos"), Structure::kHinfPos);
  EXPECT_EQ(to_string(Structure::kLqgPos), "lqg-pos");
  EXPECT_TRUE(is_full_order(Structure::kLqgPos) && controls_position(Structure::kHinfPos));
  EXPECT_FALSE(has_position_loop(Structure::kLqgPos));
}

TEST(TuneLoadFeedback, HinfLoadIsTheC717DesignAndItsLoopIsTheLoadMeasured) {
  // hinf-load: C7.17's load-side H-infinity at the tuner's weights; its loop checked on the closed
  // loop written out in state space with the LOAD velocity measured (an independent route): the
  // load tracking at several frequencies and at the predicted bandwidth (−3 dB), integral action
  // on ωl, and a load torque rejected from ωl at DC.
  const fit::PlantModel model = test::two_mass_model(3.0, 0.01);
  const TuneResult result = tune(model, position_options(Structure::kHinfLoad));
  const Controller& c = result.controller;
  ASSERT_TRUE(c.full_order && c.full_order->hinf);
  VelocityHinfWeights w;
  w.omega_0s = c.full_order->hinf->omega_0s;
  w.omega_0t = c.full_order->hinf->omega_0t;
  const core::StateSpace k = load_side_hinf(result.plant, w).compensator;
  for (const double x : {0.05, 0.5, 2.0})
    for (Eigen::Index i = 0; i < 2; ++i)
      EXPECT_LT(std::abs(core::frequency_response(c.full_order->compensator, x, 0, i) - core::frequency_response(k, x, 0, i)),
                1e-6 * std::abs(core::frequency_response(k, x, 0, i)));
  const FrictionTwoMass m = *two_mass_realization(result.plant);
  const core::StateSpace cl = test::closed_loop_ss(two_mass_state_space(m, false), c.full_order->compensator, 1);
  const VelocityLoop loop = controller_loop(result.plant, c);
  ASSERT_TRUE(loop.measures_load());
  for (const double x : {0.01, 0.3, 1.0, 3.0, 10.0}) {
    const Complex direct = core::frequency_response(cl, x, 1, 0);
    EXPECT_LT(std::abs(loop.load_tracking(x) - direct), 1e-8 * std::abs(direct)) << x;
    EXPECT_LT(std::abs(loop.load_from_load_torque(x) - core::frequency_response(cl, x, 1, 1)),
              1e-8 * std::abs(core::frequency_response(cl, x, 1, 1)) + 1e-12) << x;
  }
  EXPECT_NEAR(std::abs(core::frequency_response(cl, c.predicted.bandwidth_load, 1, 0)), std::pow(10.0, -3.0 / 20.0), 1e-6);
  EXPECT_NEAR(std::abs(core::frequency_response(cl, 1e-7, 1, 0)), 1.0, 1e-6);
  EXPECT_LT(std::abs(core::frequency_response(cl, 1e-10, 1, 1)), 1e-6);
  EXPECT_LE(c.predicted.peak_s, 1.5 * (1.0 + 1e-3));
  EXPECT_LE(c.predicted.peak_tl, 1.5 * (1.0 + 1e-3));
  // The scan is not cut short on load feedback: a band of infeasible w0S (0.08 to 0.18 here)
  // separates the slow designs from the fast ones, and the chosen design is a fast one.
  EXPECT_GT(c.full_order->hinf->omega_0s, 0.5);
  EXPECT_GT(c.predicted.bandwidth_load, 2.0);
  // A plant with a higher mode has no two-mass load to measure.
  expect_refused_without_a_two_mass_load(model, Structure::kHinfLoad, "needs a two-mass plant");
}

TEST(TuneLoadFeedback, LqgLoadIsC717sLqgAndItsLoopIsBothVelocitiesMeasured) {
  // lqg-load: C7.17's load-side LQG (integral on ωl, Kalman filter on [ωm, ωl]) at the chosen kbw
  // and feedforward; its loop checked on the closed loop written out in state space with both
  // velocities fed back (test::two_measurement_closed_loop_ss, independent of the transfer-
  // function route the tuner analyses): load tracking and load-torque response, −3 dB at the
  // predicted load bandwidth, unit DC gain and a load torque rejected from ωl at DC.
  const fit::PlantModel model = test::two_mass_model(3.0, 0.01);
  const TuneResult result = tune(model, position_options(Structure::kLqgLoad));
  const Controller& c = result.controller;
  ASSERT_TRUE(c.full_order && !c.full_order->hinf);
  const FrictionTwoMass m = *two_mass_realization(result.plant);
  const core::StateSpace k = load_side_lqg(m, result.plant.r, c.full_order->weights).compensator;
  ASSERT_EQ(c.full_order->compensator.B.cols(), 3);
  for (const double x : {0.05, 0.5, 2.0})
    for (Eigen::Index i = 0; i < 3; ++i)
      EXPECT_LT(std::abs(core::frequency_response(c.full_order->compensator, x, 0, i) - core::frequency_response(k, x, 0, i)),
                1e-9 * std::abs(core::frequency_response(k, x, 0, i)));
  const core::StateSpace cl = test::two_measurement_closed_loop_ss(two_mass_state_space(m, false), k);
  const VelocityLoop loop = controller_loop(result.plant, c);
  ASSERT_TRUE(loop.measures_both());
  for (const double x : {0.01, 0.3, 1.0, 3.0, 10.0}) {
    const Complex direct = core::frequency_response(cl, x, 1, 0);
    EXPECT_LT(std::abs(loop.load_tracking(x) - direct), 1e-8 * std::abs(direct)) << x;
    const Complex torque = core::frequency_response(cl, x, 1, 1);
    EXPECT_LT(std::abs(loop.load_from_load_torque(x) - torque), 1e-8 * std::abs(torque) + 1e-12) << x;
  }
  EXPECT_NEAR(std::abs(core::frequency_response(cl, c.predicted.bandwidth_load, 1, 0)), std::pow(10.0, -3.0 / 20.0), 1e-6);
  EXPECT_NEAR(std::abs(core::frequency_response(cl, 1e-7, 1, 0)), 1.0, 1e-6);
  EXPECT_LT(std::abs(core::frequency_response(cl, 1e-10, 1, 1)), 1e-6);
  // The spec holds, and the automatic kbw stops where it binds (||S|| or the load tracking peak).
  EXPECT_LE(c.predicted.peak_s, 1.5 * (1.0 + 1e-3));
  EXPECT_LE(c.predicted.peak_tl, 1.5 * (1.0 + 1e-3));
  EXPECT_GT(std::max(c.predicted.peak_s, c.predicted.peak_tl), 1.5 * (1.0 - 1e-2));
  // C7.17: measuring the load is worth it. The motor-feedback LQG of the same spec on the same plant
  // reaches a slower load.
  const TuneResult motor = tune(model, position_options(Structure::kLqg));
  EXPECT_GT(c.predicted.bandwidth_load, 2.0 * motor.controller.predicted.bandwidth_load);
  // Refused where there is no two-mass load to measure, and by the motor-feedback comparison.
  expect_refused_without_a_two_mass_load(model, Structure::kLqgLoad, "lqg-load (C7.17) needs a two-mass plant");
  EXPECT_EQ(structure_from_string("lqg-load"), Structure::kLqgLoad);
  EXPECT_TRUE(measures_both(Structure::kLqgLoad) && measures_load(Structure::kLqgLoad) && is_lqg(Structure::kLqgLoad));
  EXPECT_FALSE(measures_both(Structure::kHinfLoad));
  EXPECT_THROW((void)compensator_form(Structure::kLqgLoad, k), std::invalid_argument);
}

}  // namespace tune_position_test
}  // namespace
}  // namespace servotwin::tuning
