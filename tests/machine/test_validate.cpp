// machine::validate: every bad value is reported with the name of its field.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/machine/presets.hpp"

namespace servotwin::machine {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Case {
  const char* preset;
  std::function<void(MachineConfig&)> mutate;
  const char* field;
};

template <class T>
T& controller(MachineConfig& m, std::size_t axis = 0) {
  return std::get<T>(m.axes[axis].controller);
}

std::vector<Case> cases() {
  return {
      {"fadal-pid", [](MachineConfig& m) { m.ts = 0.0; }, "ts"},
      {"fadal-pid", [](MachineConfig& m) { m.ts = kNaN; }, "ts"},
      {"fadal-pid", [](MachineConfig& m) { m.cnc.accel = -1.0; }, "cnc.accel"},
      {"fadal-pid", [](MachineConfig& m) { m.cnc.jerk = 0.0; }, "cnc.jerk"},
      {"fadal-pid", [](MachineConfig& m) { m.cnc.rapid_feed_mm_min = 0.0; }, "cnc.rapid_feed_mm_min"},
      {"fadal-pid", [](MachineConfig& m) { m.cnc.corner_angle_deg = 180.0; }, "cnc.corner_angle_deg"},
      {"fadal-pid", [](MachineConfig& m) { m.axes.clear(); }, "axes"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[1].name = "Y"; }, "axes[1].name"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[1].name = ""; }, "axes[1].name"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[1].name = "x"; }, "axes[1].name"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[1].name = "2y"; }, "axes[1].name"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].name = "x axis"; }, "axes[0].name"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].home = kInf; }, "axes[0].home"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].plant.inertia = 0.0; }, "axes[0].plant.inertia"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[1].plant.damping = -0.1; }, "axes[1].plant.damping"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].plant.gain = kNaN; }, "axes[0].plant.gain"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.friction.coulomb_pos = -1.0; },
       "axes[0].nonlinear.friction.coulomb_pos"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.friction.coulomb_neg = 1.0; },
       "axes[0].nonlinear.friction.coulomb_neg"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.friction.static_pos = 10.0; },
       "axes[0].nonlinear.friction.static_pos"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.friction.static_neg = -10.0; },
       "axes[0].nonlinear.friction.static_neg"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.backlash.width = -0.01; },
       "axes[0].nonlinear.backlash.width"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.u_max = 0.0; }, "axes[0].nonlinear.u_max"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.u_max = kNaN; }, "axes[0].nonlinear.u_max"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.dac_bits = 1; }, "axes[0].nonlinear.dac_bits"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.dac_bits = 40; }, "axes[0].nonlinear.dac_bits"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.dac_range = 0.0; }, "axes[0].nonlinear.dac_range"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.encoder_resolution = -1e-3; },
       "axes[0].nonlinear.encoder_resolution"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.encoder_noise_std = kInf; },
       "axes[0].nonlinear.encoder_noise_std"},
      {"fadal-pid", [](MachineConfig& m) { m.axes[0].nonlinear.delay_samples = 2; }, "axes[0].nonlinear.delay_samples"},
      {"fadal-pid", [](MachineConfig& m) { controller<PidController>(m).kp = -1.0; }, "axes[0].controller.kp"},
      {"fadal-pid", [](MachineConfig& m) { controller<PidController>(m).ki = kNaN; }, "axes[0].controller.ki"},
      {"fadal-pid", [](MachineConfig& m) { controller<PidController>(m).kd = -1.0; }, "axes[0].controller.kd"},
      {"fadal-pid", [](MachineConfig& m) { controller<PidController>(m, 1).vel_ff = kInf; }, "axes[1].controller.vel_ff"},
      {"fadal-pid", [](MachineConfig& m) { controller<PidController>(m).acc_ff = kNaN; }, "axes[0].controller.acc_ff"},
      {"fadal-pid", [](MachineConfig& m) { controller<PidController>(m).kp = 1e5; }, "axes[0].controller"},
      {"fadal-ppi", [](MachineConfig& m) { controller<PPiController>(m).kp = -30.0; }, "axes[0].controller.kp"},
      {"fadal-ppi", [](MachineConfig& m) { controller<PPiController>(m).kv = kNaN; }, "axes[0].controller.kv"},
      {"fadal-ppi", [](MachineConfig& m) { controller<PPiController>(m).ki = -1.0; }, "axes[0].controller.ki"},
      {"fadal-ppi", [](MachineConfig& m) { controller<PPiController>(m).kv = 5.0; }, "axes[0].controller"},
      {"fadal-smc", [](MachineConfig& m) { controller<SlidingModeController>(m).lambda = 0.0; },
       "axes[0].controller.lambda"},
      {"fadal-smc", [](MachineConfig& m) { controller<SlidingModeController>(m).ks = -1.0; }, "axes[0].controller.ks"},
      {"fadal-smc", [](MachineConfig& m) { controller<SlidingModeController>(m).rho = kNaN; }, "axes[0].controller.rho"},
      {"fadal-smc", [](MachineConfig& m) { controller<SlidingModeController>(m).model_inertia = 0.0; },
       "axes[0].controller.model_inertia"},
      {"fadal-smc", [](MachineConfig& m) { controller<SlidingModeController>(m).model_damping = -1.0; },
       "axes[0].controller.model_damping"},
      {"fadal-smc", [](MachineConfig& m) { controller<SlidingModeController>(m).model_gain = -100.0; },
       "axes[0].controller.model_gain"},
      {"ballscrew-zpetc", [](MachineConfig& m) { controller<PolePlacementController>(m).wn_hz = 0.0; },
       "axes[0].controller.wn_hz"},
      {"ballscrew-zpetc",
       [](MachineConfig& m) {
         controller<PolePlacementController>(m).wn_hz = 600.0;
         controller<PolePlacementController>(m).zeta = 0.1;
       },
       "axes[0].controller.wn_hz"},
      {"ballscrew-zpetc", [](MachineConfig& m) { controller<PolePlacementController>(m).zeta = -0.7; },
       "axes[0].controller.zeta"},
      {"ballscrew-zpetc", [](MachineConfig& m) { controller<PolePlacementController>(m).kalman_process_noise = 0.0; },
       "axes[0].controller.kalman_process_noise"},
      {"ballscrew-zpetc",
       [](MachineConfig& m) { controller<PolePlacementController>(m, 1).kalman_measurement_noise = kNaN; },
       "axes[1].controller.kalman_measurement_noise"},
  };
}

TEST(Validate, PresetsAreValid) {
  for (const auto& name : preset_names()) EXPECT_NO_THROW(validate(preset(name))) << name;
}

TEST(Validate, NamesTheFieldOfEveryBadValue) {
  for (const Case& c : cases()) {
    MachineConfig m = preset(c.preset);
    c.mutate(m);
    try {
      validate(m);
      ADD_FAILURE() << "no error for " << c.field;
    } catch (const core::InputError& e) {
      EXPECT_EQ(e.where().field, c.field) << e.what();
      EXPECT_FALSE(e.reason().empty());
      EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
    }
  }
}

TEST(Validate, MessagesSayWhatWasExpectedAndFound) {
  MachineConfig m = preset("fadal-pid");
  m.axes[0].plant.inertia = -0.5;
  try {
    validate(m);
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(e.reason().find("> 0"), std::string::npos) << e.reason();
    EXPECT_NE(e.reason().find("-0.5"), std::string::npos) << e.reason();
  }
  m = preset("fadal-pid");
  std::get<PidController>(m.axes[0].controller).kp = 1e5;
  try {
    validate(m);
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(e.reason().find("unstable"), std::string::npos) << e.reason();
  }
}

TEST(Validate, FindsAxesCaseInsensitively) {
  const MachineConfig m = preset("fadal-smc");
  ASSERT_NE(m.find("Y"), nullptr);
  EXPECT_EQ(m.find("Y")->name, "y");
  EXPECT_EQ(m.find("z"), nullptr);
}

}  // namespace
}  // namespace servotwin::machine
