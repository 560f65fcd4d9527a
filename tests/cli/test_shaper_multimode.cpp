// `servotwin shaper multimode` end to end. Expected values: the dissertation's E22 (catalog E22:
// ZV + first derivative per mode at ω = 1, 2.25, 3.4 rad/s, ζ = 0.1, J2 with k = 1, n = 14,
// Tp = 0.68 s -> T_f = 8.84 s, first pulse 0.1492) and E21 (3 x ZVD convolved: 27 pulses,
// T_f = 10.979 s).
#include <nlohmann/json.hpp>
#include <numbers>

#include "cli_support.hpp"
#include "servotwin/io/shaper_json.hpp"
#include "servotwin/shaping/sensitivity.hpp"

namespace servotwin::cli_test {
namespace {

// The modes of E21/E22 in Hz (the CLI's unit).
const std::string kModes = [] {
  std::string modes;
  for (double w : {1.0, 2.25, 3.4}) modes += " --mode-hz " + std::to_string(w / (2.0 * std::numbers::pi)) + ":0.1";
  return modes;
}();

TEST_F(Cli, MultimodeLpReproducesE22) {
  const Result r = run("shaper multimode" + kModes + " --derivatives 1 --tp 0.68 --n 14 --json -o lp.json");
  ASSERT_EQ(r.status, 0) << r.err;
  const io::LoadedShaper s = io::load_shaper(path("lp.json").string());
  EXPECT_EQ(s.shaper.type, "lp");
  EXPECT_NEAR(s.shaper.duration(), 8.84, 1e-9);
  EXPECT_NEAR(s.shaper.amplitudes.front(), 0.1492, 5e-4);
  for (double w : {1.0, 2.25, 3.4}) EXPECT_LT(shaping::residual_vibration(s.shaper, w, 0.1), 1e-6) << w;
}

TEST_F(Cli, MultimodeConvolutionReproducesE21) {
  const Result r = run("shaper multimode" + kModes + " --method convolve --family zvd --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const io::LoadedShaper s = io::parse_shaper_json(r.out, "stdout");
  EXPECT_EQ(s.shaper.times.size(), 27u);
  EXPECT_NEAR(s.shaper.duration(), 10.979, 5e-4);
}

TEST_F(Cli, MultimodeBadInput) {
  Result r = run("shaper multimode --mode-hz 0.2:1.5 --ts 0.01");
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("--mode-hz"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("damping"), std::string::npos) << r.err;
  r = run("shaper multimode" + kModes + " --derivatives 1 --tp 0.68 --n 5");  // fewer pulses than conditions
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("infeasible"), std::string::npos) << r.err;
  r = run("shaper multimode --mode-hz 600:0.1 --ts 0.001");  // beyond Nyquist
  EXPECT_EQ(r.status, 3) << r.err;
}

}  // namespace
}  // namespace servotwin::cli_test
