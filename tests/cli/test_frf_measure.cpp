// `servotwin frf measure` end to end, then `fit --report` on its output: the measured file is a
// valid servotwin.frf/1 response whose fit gives the motor-bench preset's modes (53 and 76 Hz by the
// preset's construction, machine/flexible_presets.hpp), the trace is written on request, and bad
// requests are named. The 0.5 % / 20 % / 30 s checks live in tests/vcnc/test_frf_experiment.cpp.
#include <cmath>
#include <numbers>

#include "cli_support.hpp"
#include "servotwin/io/frf_csv.hpp"
#include "servotwin/io/plant_model_json.hpp"

namespace servotwin::cli_test {
namespace {

TEST_F(Cli, FrfMeasureThenFitFindsTheMotorBenchModes) {
  const Result m = run("frf measure --plant motor-bench --range-hz 1:500 -o frf.csv --trace trace.csv");
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_NE(m.out.find("antiresonance near"), std::string::npos) << m.out;
  const core::FrequencyResponse r = io::read_frf_file(path("frf.csv").string());
  EXPECT_GE(r.size(), 30u);
  ASSERT_TRUE(r.duration_s.has_value());
  EXPECT_EQ(r.quality_kind, core::QualityKind::kThd);
  const std::string trace = slurp(path("trace.csv"));
  EXPECT_EQ(trace.rfind("t,mv,pv,f_hz,amplitude,thd,state\n", 0), 0u);
  EXPECT_NE(trace.find(",done"), std::string::npos);

  const Result f = run("fit frf.csv --delay -o plant_model.json --report fit.html");
  ASSERT_EQ(f.status, 0) << f.err;
  const io::LoadedPlantModel model = io::load_plant_model(path("plant_model.json").string());
  ASSERT_EQ(model.model.modes.size(), 1u);
  EXPECT_NEAR(model.model.modes[0].antiresonance.omega_rad_s / (2 * std::numbers::pi), 53.0, 0.3);
  EXPECT_NEAR(model.model.modes[0].resonance.omega_rad_s / (2 * std::numbers::pi), 76.0, 0.4);
  const std::string html = slurp(path("fit.html"));
  EXPECT_NE(html.find("Two-mass parameters"), std::string::npos);

  // Neither output is replaced without --force.
  const Result again = run("frf measure --plant motor-bench -o frf.csv");
  EXPECT_EQ(again.status, 3) << again.err;
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
}

TEST_F(Cli, FrfMeasureNamesWhatCannotBeMeasured) {
  Result r = run("frf measure --plant motor-bench --range-hz 1:900 -o frf.csv");  // 8 kHz: fs/10 = 800 Hz
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("--range-hz"), std::string::npos) << r.err;
  r = run("frf measure --plant motor-bench --range-hz 500 -o frf.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("BEGIN:END"), std::string::npos) << r.err;
  r = run("frf measure --plant no-such-plant -o frf.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("motor-bench"), std::string::npos) << r.err;  // lists the presets
  EXPECT_FALSE(fs::exists(path("frf.csv")));
}

}  // namespace
}  // namespace servotwin::cli_test
