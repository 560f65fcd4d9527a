// Shapers as firmwares compute them (shaping/firmware.hpp). References: servotwin's own zv, zvd
// and mzv (identical by definition, families.hpp's file comment), the residual vibration of
// Klipper's EI-family curve fits recorded by tools/reference/shaping_reference.py
// (ei_family.json, "klipper_fit_difference", computed with scipy from Singhose's fits), and
// Klipper's ZVD at 100 Hz without damping, [1, 2, 1] / 4 at 0, 5, 10 ms (its shaper_defs.py).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/firmware.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::shaping {
namespace {

constexpr double kTwoPiF = 2.0 * std::numbers::pi;

TEST(Firmware, KlipperZvZvdMzvAreServotwinsOwn) {
  for (const double zeta : {0.0, 0.05, 0.1, 0.3}) {
    for (const auto& [name, type] : {std::pair{"zv", ShaperType::kZv}, {"zvd", ShaperType::kZvd}, {"mzv", ShaperType::kMzv}}) {
      SCOPED_TRACE(std::string(name) + " zeta " + std::to_string(zeta));
      const Shaper ours = design_shaper(type, kTwoPiF * 42.0, zeta);
      const Shaper theirs = klipper_shaper(name, kTwoPiF * 42.0, zeta);
      ASSERT_EQ(ours.times.size(), theirs.times.size());
      for (std::size_t i = 0; i < ours.times.size(); ++i) {
        EXPECT_NEAR(theirs.times[i], ours.times[i], 1e-15);
        EXPECT_NEAR(theirs.amplitudes[i], ours.amplitudes[i], 1e-14);
      }
    }
  }
  const Shaper zvd = klipper_shaper("zvd", kTwoPiF * 100.0, 0.0);
  EXPECT_EQ(zvd.times, (std::vector<double>{0.0, 0.005, 0.01}));
  EXPECT_EQ(zvd.amplitudes, (std::vector<double>{0.25, 0.5, 0.25}));
}

TEST(Firmware, KlipperEiFamilyLeavesTheReferenceVibration) {
  const nlohmann::json data = test::load_fixture("ei_family.json");
  std::size_t checked = 0;
  for (const auto& c : data.at("cases")) {
    if (!c.contains("klipper_fit_difference")) continue;
    const std::string type = c.at("type");
    const double zeta = c.at("zeta");
    SCOPED_TRACE(type + " zeta " + std::to_string(zeta));
    const double omega = kTwoPiF * 40.0;
    const Shaper k = klipper_shaper(type, omega, zeta);
    EXPECT_NEAR(residual_vibration(k, omega, zeta), c.at("klipper_fit_difference").at("klipper_residual_at_design").get<double>(),
                1e-12);
    double sum = 0.0;
    for (const double a : k.amplitudes) sum += a;
    EXPECT_NEAR(sum, 1.0, 1e-15);
    ++checked;
  }
  EXPECT_GE(checked, 12u);
}

TEST(Firmware, KlipperTypesAndLimits) {
  EXPECT_TRUE(klipper_has("3hump_ei"));
  EXPECT_FALSE(klipper_has("zvdd"));
  EXPECT_FALSE(klipper_has("zv4"));
  EXPECT_EQ(klipper_max_damping("ei"), 0.4);
  EXPECT_EQ(klipper_max_damping("3hump_ei"), 0.2);
  EXPECT_THAT([] { (void)klipper_shaper("zv4", 1.0, 0.1); }, testing::ThrowsMessage<core::InputError>(testing::HasSubstr("zv, mzv")));
  EXPECT_THROW((void)klipper_shaper("zv", -1.0, 0.1), core::InputError);
  EXPECT_THROW((void)klipper_shaper("zv", 1.0, 1.0), core::InputError);
}

}  // namespace
}  // namespace servotwin::shaping
