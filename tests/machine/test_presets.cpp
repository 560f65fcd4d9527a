// Named machines: the parameters derived from thesis Tables 3.3-3.5 and section 3.4.2, and the
// settings every preset carries. (That the presets' closed loops reproduce the tables is
// checked in test_closed_loop.cpp.)

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"
#include "servotwin/machine/presets.hpp"

namespace servotwin::machine {
namespace {

TEST(Presets, NamesAndCommonSettings) {
  const std::vector<std::string> names = {"fadal-ppi", "fadal-pid", "fadal-smc", "ballscrew-zpetc"};
  EXPECT_EQ(preset_names(), names);
  for (const auto& name : names) {
    const MachineConfig m = preset(name);
    EXPECT_EQ(m.name, name);
    EXPECT_FALSE(m.description.empty());
    EXPECT_EQ(m.ts, 0.001);
    EXPECT_EQ(m.cnc.accel, 2000.0);
    EXPECT_FALSE(m.cnc.jerk.has_value());
    EXPECT_EQ(m.cnc.rapid_feed_mm_min, 12000.0);
    ASSERT_EQ(m.axes.size(), 2u);
    EXPECT_EQ(m.axes[0].name, "x");
    EXPECT_EQ(m.axes[1].name, "y");
    for (const auto& a : m.axes) {
      EXPECT_EQ(a.plant.inertia, 0.1);
      EXPECT_EQ(a.plant.gain, 100.0);
      EXPECT_EQ(a.nonlinear.u_max, 10.0);
      EXPECT_EQ(a.nonlinear.dac_bits, 16);
      EXPECT_EQ(a.nonlinear.dac_range, 10.0);
      EXPECT_EQ(a.nonlinear.encoder_resolution, name == "ballscrew-zpetc" ? 0.00125 : 0.001);
      EXPECT_EQ(a.nonlinear.encoder_noise_std, 0.0);
      EXPECT_EQ(a.nonlinear.delay_samples, 0);
      EXPECT_EQ(a.nonlinear.backlash.width, 0.0);
    }
  }
}

TEST(Presets, UnknownNameListsTheKnownOnes) {
  try {
    preset("fadal");
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "preset");
    for (const auto& n : preset_names()) EXPECT_NE(e.reason().find(n), std::string::npos) << e.reason();
  }
}

TEST(Presets, FadalPidParametersFollowFromTable34) {
  // K/J = 1000: kd = b1/1000, kp = a2/1000, ki = a3/1000, B/J = a1 - b1; F = d J.
  const MachineConfig m = preset("fadal-pid");
  const auto& x = std::get<PidController>(m.axes[0].controller);
  EXPECT_NEAR(x.kp, 44.35623, 1e-12);
  EXPECT_NEAR(x.ki, 316.83021, 1e-12);
  EXPECT_NEAR(x.kd, 0.19010, 1e-15);
  EXPECT_EQ(x.vel_ff, 0.0);
  EXPECT_NEAR(m.axes[0].plant.damping / 0.1, 2.55, 1e-12);
  EXPECT_NEAR(m.axes[1].plant.damping / 0.1, 2.90, 1e-12);
  EXPECT_NEAR(m.axes[0].nonlinear.friction.coulomb_pos, 44.1, 1e-12);
  EXPECT_NEAR(m.axes[0].nonlinear.friction.coulomb_neg, -30.2, 1e-12);
  EXPECT_NEAR(m.axes[1].nonlinear.friction.coulomb_pos, 40.9, 1e-12);
  EXPECT_NEAR(m.axes[1].nonlinear.friction.coulomb_neg, -38.8, 1e-12);
  EXPECT_FALSE(m.axes[0].nonlinear.friction.static_pos.has_value());  // stiction = Coulomb level
}

TEST(Presets, FadalPPiParametersFollowFromTable33) {
  // K ki/J = a2 - b2, kp = a3/(a2 - b2), K kv/J = b2/kp, B/J = a1 - K kv/J.
  const MachineConfig m = preset("fadal-ppi");
  const auto& x = std::get<PPiController>(m.axes[0].controller);
  EXPECT_NEAR(x.kp, 30.0, 1e-5);
  EXPECT_NEAR(x.ki, (62009.83 - 11106.33) / 1000.0, 1e-12);
  EXPECT_NEAR(x.kv, 11106.33 / x.kp / 1000.0, 1e-15);
  EXPECT_NEAR(m.axes[0].plant.damping / 0.1, 372.76 - 11106.33 / x.kp, 1e-9);
  EXPECT_NEAR(m.axes[0].plant.damping / 0.1, 2.549, 1e-3);  // vs 2.55 from the PID table
  EXPECT_NEAR(m.axes[1].plant.damping / 0.1, 2.899, 1e-3);
}

TEST(Presets, FadalSmcParametersFollowFromTable35) {
  // (s + lambda)(s^2 + (B + K ks)/J s + K rho/J): lambda is the printed polynomial's real root.
  const MachineConfig m = preset("fadal-smc");
  for (std::size_t i = 0; i < 2; ++i) {
    const auto& c = std::get<SlidingModeController>(m.axes[i].controller);
    const double a1 = i == 0 ? 390.10 : 493.09, a3 = i == 0 ? 3801962.50 : 5861711.35;
    const double lam = c.lambda;
    EXPECT_NEAR(((-lam + a1) * -lam + (i == 0 ? 57029.44 : 87925.67)) * -lam + a3, 0.0, 1e-6 * a3);
    EXPECT_NEAR(lam / (2 * std::numbers::pi), 31.83, 0.005);  // the real pole of Table 3.5
    EXPECT_NEAR(c.rho, a3 / lam / 1000.0, 1e-12);
    EXPECT_NEAR(m.axes[i].plant.damping / 0.1 + 1000.0 * c.ks, a1 - lam, 1e-9);
    EXPECT_FALSE(c.model_inertia.has_value());
  }
  EXPECT_NEAR(m.axes[0].plant.damping / 0.1, 2.55, 1e-12);  // plant as in the PID preset
  EXPECT_NEAR(m.axes[1].plant.damping / 0.1, 2.90, 1e-12);
}

TEST(Presets, BallscrewFollowsSection342) {
  const MachineConfig m = preset("ballscrew-zpetc");
  for (const auto& a : m.axes) {
    const auto& c = std::get<PolePlacementController>(a.controller);
    EXPECT_EQ(c.wn_hz, 30.0);
    EXPECT_EQ(c.zeta, 0.7);
    EXPECT_TRUE(c.zpetc);
    // B/J from the closed-loop zero -0.99937 (~ -1 + B ts / (3 J)).
    EXPECT_NEAR(a.plant.damping / a.plant.inertia, 3.0 * (1.0 - 0.99937) / 1e-3, 0.01);
    EXPECT_NEAR(a.nonlinear.friction.coulomb_pos / a.plant.inertia, 1030.0, 1e-9);
    EXPECT_NEAR(a.nonlinear.friction.coulomb_neg / a.plant.inertia, -1000.0, 1e-9);
  }
}

}  // namespace
}  // namespace servotwin::machine
