// `servotwin shaper select` end to end. Expected values: Klipper's own recommendation printed in
// data/klipper-voron24-psd/README.md (current Klipper 84104bb: mzv @ 63.4 Hz for X, smoothing
// 0.051), the E10 table plant's resonance (ωn = 3 rad/s, ζ = 0.15: catalog E10) for the
// plant-model route, and io::load_shaper for the round trip of the JSON output.
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>

#include "cli_support.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/io/frf_csv.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::cli_test {
namespace {

const std::string kVoronX = std::string(SERVOTWIN_REPO_DATA_DIR) + "/klipper-voron24-psd/resonances_x_20221231_212825.csv";

TEST_F(Cli, SelectFromKlipperSpectrumRecommendsMzvLikeKlipper) {
  const Result r = run("shaper select '" + kVoronX + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("Recommended"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mzv"), std::string::npos) << r.out;

  // At Klipper's smoothing the least-vibration shaper is Klipper's own pick.
  const Result j = run("shaper select '" + kVoronX + "' --max-smoothing 0.0515 --json -o pick.json");
  ASSERT_EQ(j.status, 0) << j.err;
  const io::LoadedShaper pick = io::load_shaper(path("pick.json").string());  // select's JSON reads back
  EXPECT_EQ(pick.shaper.type, "mzv");
  EXPECT_NEAR(pick.shaper.omega / (2.0 * std::numbers::pi), 63.4, 1.3);
  const auto document = nlohmann::json::parse(slurp(path("pick.json")));
  EXPECT_TRUE(document.contains("alternatives"));
  EXPECT_TRUE(document.contains("reasons"));
}

TEST_F(Cli, SelectFromKlipperSpectraRecommendsWhatKlipperCanRun) {
  // Every real spectrum of data/: by default a Klipper type, exported as Klipper's section;
  // with --any-shaper the gain over that pick is printed when the best is not Klipper's.
  std::size_t gains = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(std::string(SERVOTWIN_REPO_DATA_DIR))) {
    const std::string file = entry.path().string();
    if (entry.path().extension() != ".csv" || file.find("klipper-") == std::string::npos) continue;
    SCOPED_TRACE(file);
    const Result r = run("shaper select '" + file + "' --export klipper");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("[input_shaper]\nshaper_type_x: "), std::string::npos) << r.out;
    const Result any = run("shaper select '" + file + "' --any-shaper");
    ASSERT_EQ(any.status, 0) << any.err;
    gains += any.out.find("against the best shaper Klipper can run") != std::string::npos;
  }
  EXPECT_GE(gains, 1u);
}

TEST_F(Cli, SelectFromFittedPlantModelCancelsItsResonance) {
  // E10's table plant: (0.5 s^2 + 0.06 s + 0.5)/(s^3 + 1.1 s^2 + 9.18 s + 1.8), resonance 3 rad/s,
  // damping 0.15 — measured, fitted, then selected from the fitted model.
  const core::TransferFunction tf(core::Polynomial{0.5, 0.06, 0.5}, core::Polynomial{1.0, 1.1, 9.18, 1.8});
  core::FrequencyResponse response;
  for (double w : core::log_space(0.05, 15.0, 30)) {
    core::FrequencyPoint p;
    p.freq_hz = w / (2.0 * std::numbers::pi);
    p.value = tf.frequency_response(w);
    response.points.push_back(p);
  }
  std::ostringstream csv;
  io::write_frf_csv(csv, response);
  write("frf.csv", csv.str());
  ASSERT_EQ(run("fit frf.csv --model two-mass -o plant_model.json").status, 0);
  const Result r = run("shaper select plant_model.json --json -o shaper.json");
  ASSERT_EQ(r.status, 0) << r.err;
  const io::LoadedShaper s = io::load_shaper(path("shaper.json").string());
  EXPECT_NEAR(s.shaper.omega, 3.0, 0.01);
  EXPECT_NEAR(s.shaper.zeta, 0.15, 0.005);  // the fitted damping is used, not an assumed 0.1
  EXPECT_LT(shaping::residual_vibration(s.shaper, 3.0, 0.15), 0.01);
}

TEST_F(Cli, SelectBadInput) {
  write("bad.csv", "freq,psd_x,psd_y,psd_z,psd_xyz\n0,1,1,1,3\n1.2,1,1,1,3\n2.5,-1,1,1,3\n3.7,1,1,1,3\n"
                   "5,1,1,1,3\n6.2,1,1,1,3\n7.5,1,1,1,3\n8.7,1,1,1,3\n10,1,1,1,3\n");
  Result r = run("shaper select bad.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("bad.csv:4"), std::string::npos) << r.err;
  r = run("shaper select '" + kVoronX + "' --axis w");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--axis"), std::string::npos) << r.err;
  r = run("shaper select missing.csv");
  EXPECT_NE(r.status, 0);
}

}  // namespace
}  // namespace servotwin::cli_test
