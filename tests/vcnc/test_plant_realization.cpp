// Fitted plant models as simulated plants (vcnc/plant_realization.hpp). References: a two-mass
// chain of known parameters (the round trip chain -> transfer function -> fitted-model form ->
// two-mass realization returns them, C3.12's relations being exact for a frictionless shaft
// model), and the model's own response for the transfer-function realization.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/vcnc/plant_realization.hpp"

namespace servotwin::vcnc {
namespace {

fit::PlantModel realization_model_of(const machine::MassChain& chain) {
  return fit::plant_model_from_transfer_function(
      machine::mass_chain_transfer_function(chain, machine::PlantOutput::MotorVelocity));
}

TEST(PlantRealization, TwoMassRoundTripReturnsTheChain) {
  // Im 0.005, Il 0.0051, k 570, b 0.08, no friction to ground: the rigid mode is an integrator.
  const machine::MassChain chain = machine::two_mass(0.005, 0.0051, 570.0, 0.08);
  const fit::PlantModel model = realization_model_of(chain);
  ASSERT_EQ(model.rigid, fit::RigidKind::kIntegrator);
  const machine::PlantConfig plant = realize_plant_model(model, Realization::kTwoMass, 1e-4);
  const auto& back = std::get<machine::MassChain>(plant.model);
  EXPECT_NEAR(back.inertia[0], 0.005, 1e-9 * 0.005);
  EXPECT_NEAR(back.inertia[1], 0.0051, 1e-9 * 0.0051);
  EXPECT_NEAR(back.stiffness[0], 570.0, 1e-9 * 570.0);
  EXPECT_NEAR(back.damping_of(0), 0.08, 1e-9 * 0.08);
  EXPECT_EQ(back.viscous_of(0), 0.0);
  EXPECT_EQ(plant.settings.ts, 1e-4);
  EXPECT_EQ(plant.settings.output, machine::PlantOutput::MotorVelocity);
}

TEST(PlantRealization, TransferFunctionKeepsTheModelsResponseAndDelay) {
  fit::PlantModel model;
  model.gain = 200.0;
  model.rigid_pole_rad_s = 0.9;
  model.modes.push_back({{2 * std::numbers::pi * 53.0, 0.02}, {2 * std::numbers::pi * 76.0, 0.025}});
  model.delay_s = 0.00045;  // 3.6 samples of 125 µs: 3.1 after the hold's half sample -> 3
  model.output = fit::OutputKind::kPosition;
  const machine::PlantConfig plant = realize_plant_model(model, Realization::kTransferFunction, 1.25e-4);
  const auto& tf = std::get<machine::TransferFunctionModel>(plant.model).tf;
  for (double f : {1.0, 53.0, 76.0, 300.0}) {
    const std::complex<double> s(0.0, 2.0 * std::numbers::pi * f);
    const std::complex<double> expected = model.response(s.imag()) * std::exp(s * *model.delay_s);
    EXPECT_LT(std::abs(tf(s) - expected), 1e-9 * std::abs(expected)) << f;
  }
  EXPECT_EQ(plant.settings.delay_samples, 3);
  EXPECT_EQ(plant.settings.output, machine::PlantOutput::MotorPosition);
}

TEST(PlantRealization, RefusesWhatItCannotRealize) {
  fit::PlantModel rigid;
  rigid.gain = 10.0;
  rigid.rigid_pole_rad_s = 1.0;
  try {
    (void)realize_plant_model(rigid, Realization::kTwoMass, 1e-3);
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "model");
    EXPECT_THAT(e.reason(), ::testing::HasSubstr("needs one flexible mode; the model has 0"));
  }
  try {
    (void)realize_plant_model(rigid, Realization::kTransferFunction, 0.0);
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "ts");
  }
}

}  // namespace
}  // namespace servotwin::vcnc
