// Issue 25 §5 validation: the automatic notch on a PI limited by a higher mode (three-mass chain)
// and on testbed-2, judged as the issue asks: the load bandwidth at the same Ms/Mt (the tuner's
// analysis against its own design without the notch), and the discrete controller with its
// discrete biquads run on the true plant with its nonlinearities (vcnc::simulate_drive: friction,
// backlash, the drive's sample-and-hold) settling where the linear loop does.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "servotwin/fit/plant_model.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/machine/flexible_presets.hpp"
#include "servotwin/tuning/tune.hpp"
#include "servotwin/vcnc/drive_simulation.hpp"

namespace servotwin::validation {
namespace {

constexpr double kTs = 1.0 / 8000.0;
constexpr double kCurrentLag = 3e-4;

/// Motor 2e-3, intermediate 1e-3, load 6e-3 kg m², shafts 2500 and 400 N m/rad, light damping.
/// Its modes (numpy eigenvalues of the chain): antiresonances 38.1 and 271.5 Hz, resonances 68.7
/// and 319.5 Hz; r = 1.80 (C7.4's sweet spot: the PI damps the first mode). With the drive's
/// current loop (0.3 ms) and a sample of transport delay the second mode, collocated but lagged,
/// sets ||S||: the PI is limited by it (measured: omega* 0.28 omega_z at ||S|| = Ms = 1.5).
machine::MassChain three_mass_chain() {
  machine::MassChain c;
  c.inertia = {2e-3, 1e-3, 6e-3};
  c.stiffness = {2500.0, 400.0};
  c.damping = {0.02, 0.01};
  return c;
}

tuning::TuneOptions three_mass_options() {
  tuning::TuneOptions o;
  o.ts = kTs;
  o.hf.current_lag_s = kCurrentLag;
  o.hf.delay_s = 1.5 * kTs;  // a sample of transport delay and the drive's hold, as `tune` adds them
  o.chain_load = true;       // the load sits at the end of the chain
  return o;
}

/// The chain with friction on motor and load and backlash in the soft shaft, 8 kHz.
machine::PlantConfig nonlinear_three_mass() {
  machine::PlantConfig p;
  p.name = "three-mass";
  machine::MassChain c = three_mass_chain();
  c.friction = {machine::KarnoppFriction{0.01, std::nullopt, 1e-3}, {}, machine::KarnoppFriction{0.02, std::nullopt, 1e-3}};
  c.backlash = {0.0, 2e-4};
  p.model = c;
  p.settings.ts = kTs;
  p.settings.current_lag = kCurrentLag;
  p.settings.delay_samples = 1;
  return p;
}

fit::PlantModel three_mass_model() {
  return fit::plant_model_from_transfer_function(
      machine::mass_chain_transfer_function(three_mass_chain(), machine::PlantOutput::MotorVelocity), "three-mass");
}

void expect_settles(const machine::PlantConfig& plant, const tuning::Controller& c, const std::string& what) {
  const vcnc::DriveSimulation s = vcnc::simulate_drive(plant, c);
  EXPECT_TRUE(std::isfinite(s.linear_metrics.settling_time)) << what << ": the linear loop does not settle";
  EXPECT_TRUE(std::isfinite(s.metrics.settling_time)) << what << ": the loop on the nonlinear plant does not settle";
  EXPECT_LT(std::abs(s.metrics.final_error), 0.02) << what;
}

TEST(DriveFilterValidation, NotchLiftsTheThreeMassPiAndRunsOnTheNonlinearPlant) {
  tuning::TuneOptions o = three_mass_options();
  const tuning::TuneResult without = tuning::tune(three_mass_model(), o);
  o.auto_notch = true;
  const tuning::TuneResult with = tuning::tune(three_mass_model(), o);
  const tuning::Controller& c = with.controller;
  ASSERT_EQ(c.drive_filters.size(), 1u);
  EXPECT_NEAR(c.drive_filters.front().spec.frequency_hz, 319.5, 1.0);  // the second resonance
  EXPECT_NE(c.drive_filters.front().reason.find("mode 2"), std::string::npos) << c.drive_filters.front().reason;
  const double b0 = without.controller.predicted.bandwidth_load, b1 = c.predicted.bandwidth_load;
  EXPECT_GE(b1, 1.2 * b0) << "load bandwidth " << b1 << " with the notch, " << b0 << " without (normalized)";
  EXPECT_LE(c.predicted.peak_s, 1.5 * (1.0 + 1e-3));
  EXPECT_LE(c.predicted.peak_tl, 1.5 * (1.0 + 1e-3));
  expect_settles(nonlinear_three_mass(), c, "three-mass with notch");
  expect_settles(nonlinear_three_mass(), without.controller, "three-mass without notch");
}

TEST(DriveFilterValidation, NotchLiftsTheTestBedTwoPiAndRunsOnThePreset) {
  // A6 configuration 2 (r = 5.09 > sqrt(5): the PI cannot damp the 40.4 Hz resonance, C7.4), the
  // dissertation's Ms = Mt = 2.5, the preset's 2 kHz and hold.
  const machine::PlantConfig plant = machine::flexible_preset("testbed-2");
  const fit::PlantModel model = fit::plant_model_from_transfer_function(
      std::get<machine::TransferFunctionModel>(plant.model).tf, "testbed-2");
  tuning::TuneOptions o;
  o.ms = o.mt = 2.5;
  o.ts = plant.settings.ts;
  o.hf.delay_s = 0.5 * plant.settings.ts;
  const tuning::TuneResult without = tuning::tune(model, o);
  o.auto_notch = true;
  const tuning::TuneResult with = tuning::tune(model, o);
  const tuning::Controller& c = with.controller;
  ASSERT_EQ(c.drive_filters.size(), 1u);
  EXPECT_NEAR(c.drive_filters.front().spec.frequency_hz, 254.0 / (2.0 * std::numbers::pi), 0.01);
  const double b0 = without.controller.predicted.bandwidth_load, b1 = c.predicted.bandwidth_load;
  EXPECT_GE(b1, 1.2 * b0) << "load bandwidth " << b1 << " with the notch, " << b0 << " without (normalized)";
  EXPECT_LE(c.predicted.peak_s, 2.5 * (1.0 + 1e-3));
  expect_settles(plant, c, "testbed-2 with notch");
  // Under a torque limit the PI's integrator stops (conditional integration) while the notch keeps
  // filtering, as a drive runs it: the saturated step still settles without offset.
  vcnc::DriveSimulationSettings limited;
  limited.torque_limit = 0.5 * vcnc::simulate_drive(plant, c).linear_metrics.peak_torque;
  const vcnc::DriveSimulation s = vcnc::simulate_drive(plant, c, limited);
  EXPECT_TRUE(std::isfinite(s.metrics.settling_time)) << "the torque-limited loop does not settle";
  EXPECT_LT(std::abs(s.metrics.final_error), 0.02);
}

}  // namespace
}  // namespace servotwin::validation
