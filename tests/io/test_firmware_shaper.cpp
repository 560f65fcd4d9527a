// Shapers written as firmwares take them (io/firmware_shaper.hpp). Expected text from the
// firmwares' documentation and sources: Klipper's [input_shaper] keys (docs/Config_Reference.md);
// RepRapFirmware's M593 P"custom" (AxisShaper.cpp: 3.4/3.5 read H as cumulative amplitudes and T
// as the durations between impulses, 3.6 H as each amplitude and T as delays from the first;
// at most 5 impulses). The worked example is a 3-impulse shaper at 0, 5, 10 ms with 1/4, 1/2, 1/4:
// 3.5 "H0.25:0.75 T0.005:0.005", 3.6 "H0.25:0.5 T0.005:0.010".
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>
#include <sstream>

#include "servotwin/core/error.hpp"
#include "servotwin/io/firmware_shaper.hpp"
#include "servotwin/shaping/families.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace firmware_shaper_test {
namespace {

using servotwin::core::InputError;
using servotwin::shaping::Shaper;
using ::testing::HasSubstr;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

Shaper example() { return servotwin::shaping::design_shaper(servotwin::shaping::ShaperType::kZvd, kTwoPi * 100.0, 0.0); }

TEST(FirmwareShaper, KlipperSectionAndItsNotes) {
  const auto mzv = servotwin::io::klipper_config(
      servotwin::shaping::design_shaper(servotwin::shaping::ShaperType::kMzv, kTwoPi * 42.5, 0.1), 'y');
  EXPECT_EQ(mzv.text, "[input_shaper]\nshaper_type_y: mzv\nshaper_freq_y: 42.5\ndamping_ratio_y: 0.1\n");
  EXPECT_TRUE(mzv.notes.empty());
  const auto ei = servotwin::io::klipper_config(
      servotwin::shaping::design_shaper(servotwin::shaping::ShaperType::kEi, kTwoPi * 40.0, 0.1), 'x');
  ASSERT_EQ(ei.notes.size(), 1u);
  // ei_family.json: Klipper's fit leaves 5.06 % at zeta 0.1, the exact EI 5.00 %.
  EXPECT_THAT(ei.notes.front(), HasSubstr("its version leaves 5.06 % vibration at the mode, servotwin's 5.00 %"));
  EXPECT_THAT(ei.text, HasSubstr("# Klipper computes ei itself"));
  EXPECT_THAT([] { (void)servotwin::io::klipper_config(servotwin::shaping::zv4_shaper(kTwoPi * 40.0, 0.05, {0.3, 0.5, 0.0}), 'x'); },
              testing::ThrowsMessage<InputError>(HasSubstr("no 'zv4' shaper")));
  EXPECT_THAT([] {
    (void)servotwin::io::klipper_config(
        servotwin::shaping::design_shaper(servotwin::shaping::ShaperType::kThreeHumpEi, kTwoPi * 40.0, 0.25), 'x');
  }, testing::ThrowsMessage<InputError>(HasSubstr("up to 0.2")));
}

TEST(FirmwareShaper, RepRapFirmwareCustomShaperInBothVersions) {
  EXPECT_THAT(servotwin::io::rrf_m593(example(), servotwin::io::RrfVersion::V3_5).text,
              HasSubstr("M593 P\"custom\" H0.250000:0.750000 T0.0050000:0.0050000\n"));
  EXPECT_THAT(servotwin::io::rrf_m593(example(), servotwin::io::RrfVersion::V3_6).text,
              HasSubstr("M593 P\"custom\" H0.250000:0.500000 T0.0050000:0.0100000\n"));
  Shaper six = example();
  six.times = {0, 1, 2, 3, 4, 5};
  six.amplitudes.assign(6, 1.0 / 6.0);
  EXPECT_THAT([&] { (void)servotwin::io::rrf_m593(six, servotwin::io::RrfVersion::V3_5); },
              testing::ThrowsMessage<InputError>(HasSubstr("2 to 5 impulses, this one has 6")));
  Shaper negative = example();
  negative.amplitudes = {0.6, -0.2, 0.6};
  EXPECT_THROW((void)servotwin::io::rrf_m593(negative, servotwin::io::RrfVersion::V3_5), InputError);
}

TEST(FirmwareShaper, TableReadsBackExactly) {
  const Shaper s = servotwin::shaping::design_shaper(servotwin::shaping::ShaperType::kEi, kTwoPi * 33.3, 0.07);
  std::istringstream in(servotwin::io::impulse_table(s));
  std::string line;
  std::size_t i = 0;
  while (std::getline(in, line)) {
    if (line.front() == '#') continue;
    std::istringstream fields(line);
    double t = 0.0, a = 0.0;
    fields >> t >> a;
    ASSERT_LT(i, s.times.size());
    EXPECT_EQ(t, s.times[i]);
    EXPECT_EQ(a, s.amplitudes[i]);
    ++i;
  }
  EXPECT_EQ(i, s.times.size());
}

}  // namespace
}  // namespace firmware_shaper_test
