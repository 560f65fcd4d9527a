// plant_model_from_transfer_function: the inverse of PlantModel::transfer_function. Reference: the
// modal parameters a model was built from (round trip), and the closed-form two-mass quantities
// ωz = sqrt(k/Il), ωn = sqrt(k(Im + Il)/(Im Il)), K = 1/Im (catalog C3.12).
#include <gtest/gtest.h>

#include <cmath>

#include "servotwin/core/error.hpp"
#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit {
namespace {

PlantModel two_mode_model(RigidKind rigid) {
  PlantModel m;
  m.gain = 37.5;
  m.rigid = rigid;
  m.rigid_pole_rad_s = rigid == RigidKind::kRealPole ? 2.3 : 0.0;
  m.modes = {{{40.0, 0.03}, {95.0, 0.05}}, {{310.0, 0.01}, {420.0, 0.02}}};
  return m;
}

void expect_same(const PlantModel& a, const PlantModel& b) {
  EXPECT_NEAR(a.gain, b.gain, 1e-9 * b.gain);
  EXPECT_EQ(a.rigid, b.rigid);
  EXPECT_NEAR(a.rigid_pole_rad_s, b.rigid_pole_rad_s, 1e-8);
  ASSERT_EQ(a.modes.size(), b.modes.size());
  for (std::size_t i = 0; i < a.modes.size(); ++i) {
    EXPECT_NEAR(a.modes[i].antiresonance.omega_rad_s, b.modes[i].antiresonance.omega_rad_s, 1e-8 * b.modes[i].antiresonance.omega_rad_s);
    EXPECT_NEAR(a.modes[i].antiresonance.zeta, b.modes[i].antiresonance.zeta, 1e-8);
    EXPECT_NEAR(a.modes[i].resonance.omega_rad_s, b.modes[i].resonance.omega_rad_s, 1e-8 * b.modes[i].resonance.omega_rad_s);
    EXPECT_NEAR(a.modes[i].resonance.zeta, b.modes[i].resonance.zeta, 1e-8);
  }
}

TEST(PlantModelFromTransferFunction, RoundTripsModels) {
  for (RigidKind rigid : {RigidKind::kRealPole, RigidKind::kIntegrator}) {
    const PlantModel m = two_mode_model(rigid);
    expect_same(plant_model_from_transfer_function(m.transfer_function()), m);
  }
}

TEST(PlantModelFromTransferFunction, RoundTripsTheTestBedsLag) {
  // Catalog A6: K/(s + tau1) (modes) 1/(s + tau2); the faster real pole is the lag.
  PlantModel m = two_mode_model(RigidKind::kRealPole);
  m.lag_pole_rad_s = 263.2;
  const PlantModel back = plant_model_from_transfer_function(m.transfer_function());
  expect_same(back, m);
  ASSERT_TRUE(back.lag_pole_rad_s.has_value());
  EXPECT_NEAR(*back.lag_pole_rad_s, 263.2, 1e-9 * 263.2);
  m.rigid = RigidKind::kIntegrator;
  m.rigid_pole_rad_s = 0.0;
  EXPECT_NEAR(*plant_model_from_transfer_function(m.transfer_function()).lag_pole_rad_s, 263.2, 1e-9 * 263.2);
}

TEST(PlantModelFromTransferFunction, UndampedTwoMassMatchesTheClosedForms) {
  // ωm/Tm = (Il s² + k)/(s (Im Il s² + k (Im + Il))) for Im = 2, Il = 6, k = 1200, b = 0.
  const double im = 2.0, il = 6.0, k = 1200.0;
  const core::TransferFunction tf(core::Polynomial{il, 0.0, k}, core::Polynomial{im * il, 0.0, k * (im + il), 0.0});
  const PlantModel m = plant_model_from_transfer_function(tf);
  EXPECT_EQ(m.rigid, RigidKind::kIntegrator);
  EXPECT_NEAR(m.gain, 1.0 / im, 1e-12);
  ASSERT_EQ(m.modes.size(), 1u);
  EXPECT_NEAR(m.modes[0].antiresonance.omega_rad_s, std::sqrt(k / il), 1e-9);
  EXPECT_NEAR(m.modes[0].resonance.omega_rad_s, std::sqrt(k * (im + il) / (im * il)), 1e-9);
  EXPECT_EQ(m.modes[0].antiresonance.zeta, 0.0);
  EXPECT_EQ(m.modes[0].resonance.zeta, 0.0);
}

TEST(PlantModelFromTransferFunction, RefusesOtherStructuresNamingTheRoot) {
  const auto message = [](const core::TransferFunction& tf) {
    try {
      (void)plant_model_from_transfer_function(tf, "plant.tf");
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({core::Polynomial{1.0}, core::Polynomial{1.0, 1.0, 1.0, 0.0}}).find("relative degree"), std::string::npos);
  // Relative degree 2 needs the rigid pole and the lag: (s^2 + 4)/((s^2 + s + 1)(s^2 + 0.4 s + 9))
  // has neither.
  EXPECT_NE(message({core::Polynomial{1.0, 0.0, 4.0}, core::Polynomial{1.0, 1.4, 10.4, 9.4, 9.0}}).find("two real poles"),
            std::string::npos);
  EXPECT_NE(message({core::Polynomial{1.0, 4.0, 3.0}, core::Polynomial{1.0, 2.0, 5.0, 0.0}}).find("real zero at -"), std::string::npos);
  EXPECT_NE(message({core::Polynomial{1.0, 0.0, 4.0}, core::Polynomial{1.0, -1.0, 9.0, 0.0}}).find("unstable pole pair"),
            std::string::npos);
  EXPECT_NE(message({core::Polynomial{1.0, 0.0, 4.0}, core::Polynomial{1.0, 1.0, 1.0, 9.0}}).find("plant.tf"),
            std::string::npos);
}

}  // namespace
}  // namespace servotwin::fit
