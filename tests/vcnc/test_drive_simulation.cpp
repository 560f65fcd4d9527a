// Closed-loop verification of tuned controllers on the machine plant (issue 7 §5).
// References: on a plant without nonlinearities the sampled loop must reproduce the continuous
// closed-loop step responses of tuning::VelocityLoop / position_closed_loop (rational transfer
// functions composed independently of the simulation, sampled by core::step_response) to within
// the discretization error O(ts); static equilibria in closed form (integral action: the torque
// settles at the load torque, or at the Coulomb level at constant velocity); the plant's sign
// convention for the load torque (it opposes the motion, as in the dissertation).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/tuning/loop_analysis.hpp"
#include "servotwin/tuning/position_loop.hpp"
#include "servotwin/tuning/tune.hpp"
#include "servotwin/tuning/velocity_loop.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"

namespace servotwin::vcnc {
namespace {

constexpr double kTs = 2e-3;

/// A two-mass plant already in normalized units: Im = 1, ωz = sqrt(k/Il) = 1, r = sqrt(1 + Il/Im) = 2,
/// shaft damping for ζz = b/(2 sqrt(k Il)) = 0.02.
machine::PlantConfig normalized_plant() {
  machine::PlantConfig p;
  p.name = "normalized two-mass";
  p.model = machine::two_mass(1.0, 3.0, 3.0, 0.12);
  p.settings.ts = kTs;
  return p;
}

tuning::TuneResult tuned(const machine::PlantConfig& plant, tuning::Structure structure) {
  const auto tf = machine::mass_chain_transfer_function(std::get<machine::MassChain>(plant.model),
                                                        machine::PlantOutput::MotorVelocity);
  tuning::TuneOptions o;
  o.structure = structure;
  return tuning::tune(fit::plant_model_from_transfer_function(tf), o);
}

/// The continuous closed loop of the design (no HF dynamics: the sampled loop adds only ~ts/2).
tuning::ClosedLoopTransfer continuous_loop(const tuning::TuneResult& r) {
  return tuning::VelocityLoop(r.plant, tuning::normalized_controller(r.controller), false).closed_loop();
}

template <class Get>
double max_difference(const std::vector<DriveSample>& sim, const std::vector<double>& reference, Get get) {
  double worst = 0.0;
  for (std::size_t k = 0; k < sim.size() && k < reference.size(); ++k)
    worst = std::max(worst, std::abs(get(sim[k]) - reference[k]));
  return worst;
}

TEST(DriveSimulation, VelocityStepOnTheLinearPlantFollowsTheContinuousLoop) {
  const auto plant = normalized_plant();
  const auto r = tuned(plant, tuning::Structure::kPi);
  ASSERT_NEAR(r.controller.plant.omega_z, 1.0, 1e-9);  // normalized = physical for this plant
  ASSERT_NEAR(r.controller.plant.motor_inertia, 1.0, 1e-9);
  DriveSimulationSettings s;
  s.duration_s = 30.0;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);
  ASSERT_EQ(sim.samples.size(), 15001U);
  const auto loop = continuous_loop(r);
  const auto load = core::step_response(*loop.load_tracking, kTs, sim.samples.size());
  const auto motor = core::step_response(loop.motor_tracking, kTs, sim.samples.size());
  EXPECT_LT(max_difference(sim.samples, load, [](const DriveSample& x) { return x.load_velocity; }), 5e-3);
  EXPECT_LT(max_difference(sim.samples, motor, [](const DriveSample& x) { return x.motor_velocity; }), 5e-3);
  // Nothing nonlinear in this plant: the run and its linear twin are the same.
  for (std::size_t k = 0; k < sim.samples.size(); k += 997)
    EXPECT_DOUBLE_EQ(sim.samples[k].load_velocity, sim.linear_samples[k].load_velocity);
  // The metrics agree with the tuner's continuous analysis of the same loop.
  EXPECT_NEAR(sim.metrics.overshoot, r.controller.predicted.overshoot, 5e-3);
  EXPECT_NEAR(sim.metrics.settling_time, r.controller.predicted.settling_time, 0.05 * r.controller.predicted.settling_time);
  EXPECT_NEAR(sim.metrics.final_error, 0.0, 1e-4);
  EXPECT_TRUE(sim.notes.empty()) << sim.notes.front();
}

TEST(DriveSimulation, LoadStepFollowsTheContinuousLoopAndSettlesAtTheLoadTorque) {
  const auto plant = normalized_plant();
  const auto r = tuned(plant, tuning::Structure::kPi);
  DriveSimulationSettings s;
  s.test = DriveTest::kLoadStep;
  s.amplitude = 0.5;
  s.duration_s = 40.0;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);
  const auto loop = continuous_loop(r);
  auto load = core::step_response(*loop.load_from_load_torque, kTs, sim.samples.size());
  for (double& v : load) v *= s.amplitude;
  const double peak = *std::max_element(load.begin(), load.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  ASSERT_LT(peak, 0.0);  // Tl opposes the motion: the load is pushed backwards
  EXPECT_LT(max_difference(sim.samples, load, [](const DriveSample& x) { return x.load_velocity; }), 5e-3 * std::abs(peak));
  EXPECT_NEAR(sim.metrics.peak_deviation, std::abs(peak), 5e-3 * std::abs(peak));
  // Integral action: at rest again, the motor torque balances the load torque exactly.
  EXPECT_NEAR(sim.samples.back().torque_command, s.amplitude, 1e-3 * s.amplitude);
  EXPECT_NEAR(sim.samples.back().load_velocity, 0.0, 1e-3 * std::abs(peak));
  EXPECT_TRUE(std::isfinite(sim.metrics.recovery_time));
}

TEST(DriveSimulation, LqgStepAndLoadStepFollowTheContinuousLoop) {
  // The full-order compensator (5 states, Tustin at ts) in the sampled loop against the continuous
  // closed loop of its 2-DoF form; its integral action balances a load torque exactly.
  const auto plant = normalized_plant();
  const auto r = tuned(plant, tuning::Structure::kLqg);
  ASSERT_TRUE(r.controller.full_order.has_value());
  DriveSimulationSettings s;
  s.duration_s = 30.0;
  const DriveSimulation step = simulate_drive(plant, r.controller, s);
  EXPECT_EQ(step.controller.A.rows(), 5);
  ASSERT_TRUE(step.full_order.has_value());
  const auto loop = continuous_loop(r);
  const auto load = core::step_response(*loop.load_tracking, kTs, step.samples.size());
  EXPECT_LT(max_difference(step.samples, load, [](const DriveSample& x) { return x.load_velocity; }), 5e-3);
  EXPECT_NEAR(step.metrics.overshoot, r.controller.predicted.overshoot, 5e-3);
  EXPECT_NEAR(step.metrics.final_error, 0.0, 1e-4);

  s.test = DriveTest::kLoadStep;
  s.amplitude = 0.5;
  const DriveSimulation disturbance = simulate_drive(plant, r.controller, s);
  auto pushed = core::step_response(*loop.load_from_load_torque, kTs, disturbance.samples.size());
  for (double& v : pushed) v *= s.amplitude;
  const double peak = *std::max_element(pushed.begin(), pushed.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  EXPECT_LT(max_difference(disturbance.samples, pushed, [](const DriveSample& x) { return x.load_velocity; }),
            5e-3 * std::abs(peak));
  EXPECT_NEAR(disturbance.samples.back().torque_command, s.amplitude, 1e-3 * s.amplitude);
}

TEST(DriveSimulation, PositionStepFollowsTheContinuousCascade) {
  const auto plant = normalized_plant();
  const auto r = tuned(plant, tuning::Structure::kPiP);
  ASSERT_TRUE(r.controller.kpp_physical);
  DriveSimulationSettings s;
  s.duration_s = 60.0;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);
  const auto cascade = tuning::position_closed_loop(continuous_loop(r), *r.controller.kpp_normalized);
  const auto load = core::step_response(cascade.load_tracking, kTs, sim.samples.size());
  EXPECT_LT(max_difference(sim.samples, load, [](const DriveSample& x) { return x.load_position; }), 5e-3);
  EXPECT_NEAR(sim.samples.back().load_position, 1.0, 1e-3);
}

TEST(DriveSimulation, PositionLoopUnderALoadTorqueKeepsTheShaftTwist) {
  // Motor-position feedback with integral action puts the motor back at φ* = 0; the load stays
  // deflected by the static twist of the shaft, φl = −Tl/k = −0.5/3 (closed form).
  const auto plant = normalized_plant();
  const auto r = tuned(plant, tuning::Structure::kPiP);
  DriveSimulationSettings s;
  s.test = DriveTest::kLoadStep;
  s.amplitude = 0.5;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);  // automatic duration
  EXPECT_NEAR(sim.samples.back().motor_position, 0.0, 1e-3);
  EXPECT_NEAR(sim.samples.back().load_position, -0.5 / 3.0, 1e-3);
  EXPECT_NEAR(sim.metrics.final_error, 0.5 / 3.0, 1e-3);
  EXPECT_TRUE(std::isfinite(sim.metrics.recovery_time));
  EXPECT_LT(sim.metrics.recovery_time, sim.samples.back().t);
}

/// A two-mass plant far from normalized units (Im = 2, ωz = 5 rad/s, r = 2, ζz = 0.02): a scaling
/// slip between normalized and physical controllers would change the loop.
machine::PlantConfig scaled_plant() {
  machine::PlantConfig p;
  p.name = "scaled two-mass";
  p.model = machine::two_mass(2.0, 6.0, 150.0, 1.2);
  p.settings.ts = kTs / 5.0;
  return p;
}

/// The unit-step response of a normalized closed-loop function `f` of tuning result `r` at the
/// physical plant's samples (normalized time = physical time · ωz).
std::vector<double> step_at_plant_samples(const core::TransferFunction& f, const machine::PlantConfig& plant,
                                          const tuning::TuneResult& r, std::size_t samples) {
  return core::step_response(f, plant.settings.ts * r.controller.plant.omega_z, samples);
}

TEST(DriveSimulation, PositionControllersFollowTheirContinuousLoopsInPhysicalUnits) {
  // lqg-pos and hinf-pos read [φ*, φm]; de-normalized with positions scaled by ωz (to_physical),
  // Tustin at ts, they must reproduce the continuous normalized loop's load-position step (time
  // scaled by ωz) and, under a load torque, hold the motor at φ* with the load at the static twist
  // −Tl/k (closed form, k = 150).
  const auto plant = scaled_plant();
  for (const tuning::Structure structure : {tuning::Structure::kLqgPos, tuning::Structure::kHinfPos}) {
    SCOPED_TRACE(tuning::to_string(structure));
    const auto r = tuned(plant, structure);
    ASSERT_NEAR(r.controller.plant.omega_z, 5.0, 1e-9);
    ASSERT_NEAR(r.controller.plant.motor_inertia, 2.0, 1e-9);
    DriveSimulationSettings s;
    s.duration_s = 30.0;
    const DriveSimulation sim = simulate_drive(plant, r.controller, s);
    EXPECT_TRUE(controlled_variable(sim).position);
    const auto loop = tuning::integrated_outputs(continuous_loop(r));
    const auto load = step_at_plant_samples(*loop.load_tracking, plant, r, sim.samples.size());
    EXPECT_LT(max_difference(sim.samples, load, [](const DriveSample& x) { return x.load_position; }), 5e-3);
    EXPECT_NEAR(sim.samples.back().load_position, 1.0, 1e-3);
    EXPECT_NEAR(sim.metrics.overshoot, r.controller.predicted.overshoot, 5e-3);

    s.test = DriveTest::kLoadStep;
    s.amplitude = 3.0;
    const DriveSimulation disturbance = simulate_drive(plant, r.controller, s);
    EXPECT_NEAR(disturbance.samples.back().motor_position, 0.0, 1e-4);
    EXPECT_NEAR(disturbance.samples.back().load_position, -3.0 / 150.0, 1e-4);
    EXPECT_NEAR(disturbance.samples.back().torque_command, 3.0, 1e-3);
  }
}

/// A controller with integral action on the load velocity: after a load-torque step of 3 the load
/// is back at rest and the motor torque balances the load torque (closed form).
void expect_load_torque_rejected_from_the_load(const machine::PlantConfig& plant, const tuning::Controller& controller,
                                               DriveSimulationSettings s) {
  s.test = DriveTest::kLoadStep;
  s.amplitude = 3.0;
  const DriveSimulation disturbance = simulate_drive(plant, controller, s);
  EXPECT_NEAR(disturbance.samples.back().load_velocity, 0.0, 1e-4);
  EXPECT_NEAR(disturbance.samples.back().torque_command, 3.0, 1e-3);
}

TEST(DriveSimulation, LoadMeasuringControllerFollowsItsContinuousLoop) {
  // hinf-load (C7.17) reads the load velocity: the plant's encoder is moved to the load (with a
  // note), and the sampled loop follows the continuous load-feedback loop (VelocityLoop::
  // load_feedback, time scaled by omega_z) in physical units; a load torque is rejected from ωl
  // and balanced by the motor torque at rest (closed form).
  const auto plant = scaled_plant();
  const auto r = tuned(plant, tuning::Structure::kHinfLoad);
  DriveSimulationSettings s;
  s.duration_s = 20.0;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);
  ASSERT_FALSE(sim.notes.empty());
  EXPECT_NE(sim.notes.front().find("moved from motor_velocity to load_velocity"), std::string::npos) << sim.notes.front();
  const auto loop = tuning::controller_loop(r.plant, r.controller, false).closed_loop();
  const auto load = step_at_plant_samples(*loop.load_tracking, plant, r, sim.samples.size());
  EXPECT_LT(max_difference(sim.samples, load, [](const DriveSample& x) { return x.load_velocity; }), 5e-3);
  EXPECT_NEAR(sim.samples.back().load_velocity, 1.0, 1e-4);
  expect_load_torque_rejected_from_the_load(plant, r.controller, s);
}

TEST(DriveSimulation, ControllerMeasuringBothVelocitiesFollowsItsContinuousLoop) {
  // lqg-load (C7.17's LQG) reads [ω*, ωm, ωl]: the plant's sensor gives one of them and a second
  // encoder the other side. The sampled loop follows the continuous two-measurement loop
  // (VelocityLoop::two_measurements) in physical units whichever side the plant's sensor is on
  // (the channels must not be swapped), and a load torque is rejected from ωl.
  auto plant = scaled_plant();
  const auto r = tuned(plant, tuning::Structure::kLqgLoad);
  const auto loop = tuning::controller_loop(r.plant, r.controller, false).closed_loop();
  DriveSimulationSettings s;
  s.duration_s = 20.0;
  for (const auto output : {machine::PlantOutput::MotorVelocity, machine::PlantOutput::LoadVelocity}) {
    plant.settings.output = output;
    const DriveSimulation sim = simulate_drive(plant, r.controller, s);
    ASSERT_FALSE(sim.notes.empty());
    EXPECT_NE(sim.notes.front().find("measures both velocities"), std::string::npos) << sim.notes.front();
    const auto load = step_at_plant_samples(*loop.load_tracking, plant, r, sim.samples.size());
    const auto motor = step_at_plant_samples(loop.motor_tracking, plant, r, sim.samples.size());
    EXPECT_LT(max_difference(sim.samples, load, [](const DriveSample& x) { return x.load_velocity; }), 5e-3);
    // The motor swings to about 19 times the step to whip the load through the shaft: 1 % of that.
    const double motor_swing = *std::max_element(motor.begin(), motor.end());
    EXPECT_GT(motor_swing, 10.0);
    EXPECT_LT(max_difference(sim.samples, motor, [](const DriveSample& x) { return x.motor_velocity; }),
              1e-2 * motor_swing);
    EXPECT_NEAR(sim.samples.back().load_velocity, 1.0, 1e-4);
  }
  expect_load_torque_rejected_from_the_load(plant, r.controller, s);
}

TEST(DriveSimulation, IntegralActionRemovesCoulombFrictionAtConstantVelocity) {
  auto plant = normalized_plant();
  auto& chain = std::get<machine::MassChain>(plant.model);
  chain.friction = {machine::KarnoppFriction{}, machine::KarnoppFriction{0.05, 0.08, 1e-3}};
  const auto r = tuned(plant, tuning::Structure::kPi);  // designed on the linear part
  DriveSimulationSettings s;
  s.duration_s = 40.0;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);
  EXPECT_NEAR(sim.metrics.final_error, 0.0, 1e-3);
  // Sliding at constant velocity, no viscous friction: the torque equals the Coulomb level.
  EXPECT_NEAR(sim.samples.back().torque_command, 0.05, 1e-3);
  EXPECT_NEAR(sim.linear_samples.back().torque_command, 0.0, 1e-3);
}

TEST(DriveSimulation, TorqueLimitIsRespectedAndTheLoopStillSettles) {
  const auto plant = normalized_plant();
  const auto r = tuned(plant, tuning::Structure::kPi);
  DriveSimulationSettings s;
  s.duration_s = 60.0;
  const DriveSimulation free_run = simulate_drive(plant, r.controller, s);
  s.torque_limit = 0.5 * free_run.metrics.peak_torque;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);
  for (const auto& x : sim.samples) ASSERT_LE(std::abs(x.torque_command), *s.torque_limit * (1.0 + 1e-12));
  EXPECT_GT(sim.metrics.saturated_fraction, 0.0);
  EXPECT_TRUE(std::isfinite(sim.metrics.settling_time));
  EXPECT_NEAR(sim.metrics.final_error, 0.0, 1e-3);
  EXPECT_DOUBLE_EQ(sim.linear_metrics.peak_torque, free_run.metrics.peak_torque);  // the twin is unlimited
  EXPECT_FALSE(sim.notes.empty());
}

TEST(DriveSimulation, EncoderQuantizationReachesTheLoopThroughTheDifferencedPosition) {
  auto plant = normalized_plant();
  plant.settings.output = machine::PlantOutput::MotorPosition;
  const double q = 2.0 * std::numbers::pi / 4096.0;
  plant.settings.quantization = q;
  const auto r = tuned(plant, tuning::Structure::kPi);
  DriveSimulationSettings s;
  s.duration_s = 30.0;
  const DriveSimulation sim = simulate_drive(plant, r.controller, s);
  for (std::size_t k = 0; k < sim.samples.size(); k += 101)
    ASSERT_NEAR(std::remainder(sim.samples[k].measured, q), 0.0, 1e-9);
  // The velocity estimate is quantized to q/ts, but its mean is the true velocity: integral action
  // still holds the mean load velocity at the reference.
  EXPECT_NEAR(sim.metrics.final_error, 0.0, 0.01);
  EXPECT_GT(sim.metrics.residual_oscillation, 10.0 * sim.linear_metrics.residual_oscillation);
}

TEST(DriveSimulation, LinearPartDropsExactlyTheNonlinearElements) {
  auto plant = normalized_plant();
  auto& chain = std::get<machine::MassChain>(plant.model);
  chain.friction = {machine::KarnoppFriction{0.1, 0.2, 0.0}, machine::KarnoppFriction{}};
  chain.backlash = {1e-3};
  chain.viscous = {0.01, 0.02};
  plant.settings.noise_std = 1e-3;
  plant.settings.quantization = 1e-4;
  plant.settings.current_lag = 1e-3;
  plant.settings.delay_samples = 2;
  const auto linear = linear_part(plant);
  const auto& lc = std::get<machine::MassChain>(linear.model);
  EXPECT_TRUE(lc.friction.empty());
  EXPECT_TRUE(lc.backlash.empty());
  EXPECT_EQ(lc.viscous, chain.viscous);
  EXPECT_EQ(lc.inertia, chain.inertia);
  EXPECT_EQ(linear.settings.noise_std, 0.0);
  EXPECT_EQ(linear.settings.quantization, 0.0);
  EXPECT_EQ(linear.settings.current_lag, 1e-3);
  EXPECT_EQ(linear.settings.delay_samples, 2);
  EXPECT_TRUE(machine::FlexiblePlant(linear).is_linear());
}

void expect_field(const std::function<void()>& f, const std::string& field) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << field;
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, field) << e.what();
  }
}

TEST(DriveSimulation, RefusesWhatItCannotRun) {
  const auto plant = normalized_plant();
  const auto r = tuned(plant, tuning::Structure::kPi);
  auto load_output = plant;
  load_output.settings.output = machine::PlantOutput::LoadVelocity;
  expect_field([&] { (void)simulate_drive(load_output, r.controller); }, "settings.output");
  machine::PlantConfig tf_plant;
  tf_plant.model = machine::TransferFunctionModel{
      core::TransferFunction(core::Polynomial{1.0}, core::Polynomial{1.0, 1.0, 0.0})};
  tf_plant.settings.ts = kTs;
  DriveSimulationSettings load_step;
  load_step.test = DriveTest::kLoadStep;
  expect_field([&] { (void)simulate_drive(tf_plant, r.controller, load_step); }, "model");
  DriveSimulationSettings bad;
  bad.amplitude = 0.0;
  expect_field([&] { (void)simulate_drive(plant, r.controller, bad); }, "amplitude");
  bad = {};
  bad.torque_limit = -1.0;
  expect_field([&] { (void)simulate_drive(plant, r.controller, bad); }, "torque_limit");
  bad = {};
  bad.duration_s = 1e6;
  expect_field([&] { (void)simulate_drive(plant, r.controller, bad); }, "duration_s");
  auto no_kpp = tuned(plant, tuning::Structure::kPiP).controller;
  no_kpp.kpp_physical.reset();
  expect_field([&] { (void)simulate_drive(plant, no_kpp); }, "controller.kpp_physical");
}

TEST(DriveSimulation, TestNamesRoundTrip) {
  for (const DriveTest t : {DriveTest::kSetpointStep, DriveTest::kLoadStep})
    EXPECT_EQ(drive_test_from_string(to_string(t)), t);
  EXPECT_FALSE(drive_test_from_string("ramp"));
}

}  // namespace
}  // namespace servotwin::vcnc
