// Klipper resonance CSV reader (io/klipper_csv.hpp) on the real files in data/klipper-* (row
// counts and values from the files and their READMEs) and on malformed input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/io/klipper_csv.hpp"

namespace servotwin::io {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace klipper_csv_test {

std::string data(const std::string& relative) { return std::string(SERVOTWIN_REPO_DATA_DIR) + "/" + relative; }

TEST(KlipperCsv, ReadsTheRealFiles) {
  struct Expect {
    const char* file;
    std::size_t rows;
    bool normalized;
  };
  // Row counts: READMEs (ender: 160, 172, 161, 161; voron: 129); last bins checked in the files.
  for (const Expect& e : {Expect{"klipper-ender5s1-psd/resonances_x_20230321_171058.csv", 160, false},
                          Expect{"klipper-ender5s1-psd/resonances_y_20230321_171849.csv", 172, false},
                          Expect{"klipper-ender5s1-psd/calibration_data_x_20230321_165958.csv", 161, true},
                          Expect{"klipper-ender5s1-psd/calibration_data_y_20230321_165958.csv", 161, true},
                          Expect{"klipper-voron24-psd/resonances_x_20221231_212825.csv", 129, false},
                          Expect{"klipper-voron24-psd/resonances_y_20221231_213042.csv", 129, false}}) {
    const shaping::Spectrum s = load_klipper_csv(data(e.file));
    EXPECT_EQ(s.freq_hz.size(), e.rows) << e.file;
    EXPECT_EQ(s.normalized, e.normalized) << e.file;
    EXPECT_EQ(s.psd_x.size(), e.rows);
    EXPECT_EQ(s.psd_sum.size(), e.rows);
    EXPECT_EQ(s.freq_hz.front(), 0.0);
    for (std::size_t k = 0; k < s.freq_hz.size(); ++k) {
      // psd_xyz is the sum of the three axes (Klipper writes each with 4 significant digits).
      EXPECT_NEAR(s.psd_sum[k], s.psd_x[k] + s.psd_y[k] + s.psd_z[k], 2e-3 * s.psd_sum[k] + 1e-300) << e.file << " " << k;
    }
  }
  const shaping::Spectrum v = load_klipper_csv(data("klipper-voron24-psd/resonances_x_20221231_212825.csv"));
  // First data rows of the file: 0.0,7.865e+02,1.476e+02,2.155e+02,1.150e+03 / 1.6,8.231e+02,...
  EXPECT_EQ(v.psd_x[0], 786.5);
  EXPECT_EQ(v.psd_sum[0], 1150.0);
  EXPECT_EQ(v.freq_hz[1], 1.6);
  EXPECT_EQ(v.psd_x[1], 823.1);
}

std::string rows(int count, double step = 1.25) {
  std::string out;
  for (int k = 0; k < count; ++k) out += std::to_string(step * k) + ",1,2,3,6\n";
  return out;
}

shaping::Spectrum read(const std::string& text) {
  std::istringstream in(text);
  return read_klipper_csv(in, "t.csv");
}

std::string error_of(const std::string& text) {
  try {
    (void)read(text);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(KlipperCsv, RecognizesBothCalibrationDataVariants) {
  std::string marked = "freq,psd_x,psd_y,psd_z,psd_xyz,shapers:,zv(21.0),mzv(24.8)\n";
  for (int k = 0; k < 10; ++k) marked += std::to_string(1.0 + k) + ",1,2,3,6,,0.5,0.4\n";
  const shaping::Spectrum s = read(marked);
  EXPECT_TRUE(s.normalized);
  EXPECT_EQ(s.freq_hz.size(), 10u);
  EXPECT_EQ(s.psd_sum[3], 6.0);
  const shaping::Spectrum raw = read("freq,psd_x,psd_y,psd_z,psd_xyz\n" + rows(10));
  EXPECT_FALSE(raw.normalized);
  // Column order does not matter.
  const shaping::Spectrum swapped = read("psd_xyz,freq,psd_x,psd_y,psd_z\n" + std::string("6,0,1,2,3\n") +
                                         "6,1,1,2,3\n6,2,1,2,3\n6,3,1,2,3\n6,4,1,2,3\n6,5,1,2,3\n6,6,1,2,3\n6,7,1,2,9\n");
  EXPECT_EQ(swapped.freq_hz[7], 7.0);
  EXPECT_EQ(swapped.psd_z[7], 9.0);
}

TEST(KlipperCsv, LegacyCalibrationDataIsNormalized) {
  std::string text = "freq,psd_x,psd_y,psd_z,psd_xyz,zv(21.0),mzv(24.8)\n";
  for (int k = 0; k < 10; ++k) text += std::to_string(k) + ",1,2,3,6,0.5,0.4\n";
  EXPECT_TRUE(read(text).normalized);
}

TEST(KlipperCsv, BadInputNamesFileLineColumnAndValue) {
  const std::string header = "freq,psd_x,psd_y,psd_z,psd_xyz\n";
  EXPECT_THAT(error_of(header + "0,1,2,3,6\n1,1,2,3,6\n1,1,2,3,6\n" + rows(10)),
              testing::AllOf(testing::HasSubstr("t.csv:4:1"), testing::HasSubstr("does not increase")));
  EXPECT_THAT(error_of(header + "0,1,2,3,6\n1,1,-2,3,6\n" + rows(10)),
              testing::AllOf(testing::HasSubstr("t.csv:3:5"), testing::HasSubstr("-2"), testing::HasSubstr("negative")));
  EXPECT_THAT(error_of(header + "0,1,2,3,nan\n" + rows(10)),
              testing::AllOf(testing::HasSubstr("t.csv:2:9"), testing::HasSubstr("nan")));
  EXPECT_THAT(error_of(header + "0,1,2,3,x\n"), testing::AllOf(testing::HasSubstr("t.csv:2:9"), testing::HasSubstr("'x'")));
  EXPECT_THAT(error_of("freq,psd_x,psd_y,psd_xyz\n0,1,2,3\n"), testing::HasSubstr("missing column 'psd_z'"));
  EXPECT_THAT(error_of("freq,psd_x,psd_y,psd_z,psd_xyz,bogus\n"), testing::HasSubstr("unknown column 'bogus'"));
  EXPECT_THAT(error_of(header + rows(3)), testing::HasSubstr("at least 8"));
  EXPECT_THAT(error_of(header + "0,1,2,3\n"), testing::HasSubstr("t.csv:2"));
  EXPECT_THAT(error_of(""), testing::HasSubstr("empty file"));
  EXPECT_THAT(error_of("freq,psd_x,psd_y,psd_z,psd_xyz,shapers:,zv(21.0)\n0,1,2,3,6,5,0.5\n"),
              testing::HasSubstr("'shapers:'"));
  EXPECT_THAT(error_of(header + "-1,1,2,3,6\n"), testing::HasSubstr("negative"));
  EXPECT_THROW((void)load_klipper_csv("/nonexistent/r.csv"), core::InputError);
}

}  // namespace klipper_csv_test
}  // namespace
}  // namespace servotwin::io
