// The load-torque input of machine::FlexiblePlant. References: Maxwell–Betti reciprocity of the
// linear chain (ωm/Tl = −ωl/Tm: the motor's response to a load torque equals minus the load's
// response to a motor torque, the second already checked against scipy in test_flexible_plant.cpp);
// the linear and the piecewise-linear integrator must agree when the nonlinearity cannot act;
// Karnopp stiction in closed form (a load torque below the stiction level moves nothing).
#include <gtest/gtest.h>

#include <cmath>

#include "servotwin/machine/flexible_plant.hpp"

namespace servotwin::machine {
namespace {

PlantConfig two_mass_plant() {
  PlantConfig p;
  p.model = two_mass(2.0, 5.0, 400.0, 0.8, 0.05, 0.1);
  p.settings.ts = 1e-3;
  return p;
}

TEST(FlexiblePlantLoadTorque, MotorResponseToLoadTorqueIsMinusLoadResponseToMotorTorque) {
  FlexiblePlant by_motor(two_mass_plant()), by_load(two_mass_plant());
  for (int k = 0; k < 3000; ++k) {
    const PlantMeasurement a = by_motor.step(1.0, 0.0);
    const PlantMeasurement b = by_load.step(0.0, 1.0);
    ASSERT_NEAR(b.motor_velocity, -a.load_velocity, 1e-12 * (1.0 + std::abs(a.load_velocity))) << "sample " << k;
  }
}

TEST(FlexiblePlantLoadTorque, PiecewiseLinearIntegratorAgreesWithTheLinearOne) {
  // A backlash gap of 1e-12 rad never opens under a steady load: both paths integrate the same
  // linear system, the nonlinear one in sub-steps with the load torque as a force input.
  PlantConfig nl = two_mass_plant();
  std::get<MassChain>(nl.model).backlash = {1e-12};
  FlexiblePlant linear(two_mass_plant()), piecewise(nl);
  ASSERT_FALSE(piecewise.is_linear());
  double worst = 0.0, scale = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const double tl = k < 1000 ? 0.7 : -0.3;
    const PlantMeasurement a = linear.step(0.2, tl);
    const PlantMeasurement b = piecewise.step(0.2, tl);
    worst = std::max(worst, std::abs(a.load_velocity - b.load_velocity));
    scale = std::max(scale, std::abs(a.load_velocity));
  }
  EXPECT_LT(worst, 1e-6 * scale);
}

TEST(FlexiblePlantLoadTorque, LoadTorqueBelowStictionMovesNothingAndAboveItPushesBackwards) {
  PlantConfig p = two_mass_plant();
  auto& chain = std::get<MassChain>(p.model);
  chain.viscous.clear();
  chain.friction = {KarnoppFriction{}, KarnoppFriction{0.5, 1.0, 1e-4}};
  FlexiblePlant held(p);
  for (int k = 0; k < 500; ++k) {
    const PlantMeasurement m = held.step(0.0, 0.9);  // |Tl| < TS: the load sticks, the shaft carries nothing
    ASSERT_EQ(m.load_velocity, 0.0);
    ASSERT_EQ(m.motor_velocity, 0.0);
  }
  FlexiblePlant pushed(p);
  PlantMeasurement m;
  for (int k = 0; k < 500; ++k) m = pushed.step(0.0, 1.5);
  EXPECT_LT(m.load_velocity, 0.0);  // Tl opposes the motion: positive Tl drives the load backwards
  EXPECT_LT(m.motor_velocity, 0.0);
}

TEST(FlexiblePlantLoadTorque, TransferFunctionPlantIgnoresIt) {
  PlantConfig p;
  p.model = TransferFunctionModel{core::TransferFunction(core::Polynomial{1.0}, core::Polynomial{1.0, 2.0, 0.0})};
  p.settings.ts = 1e-3;
  FlexiblePlant a(p), b(p);
  for (int k = 0; k < 100; ++k) ASSERT_EQ(a.step(1.0).y, b.step(1.0, 5.0).y);
}

}  // namespace
}  // namespace servotwin::machine
