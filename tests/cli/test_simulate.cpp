// `servotwin simulate` end to end: a controller tuned from a preset runs on that preset (found
// through the controller file), its CSV holds the run, the closed-form steady state holds, and the
// errors users meet are clear.
#include <cmath>
#include <filesystem>
#include <sstream>

#include "cli_support.hpp"
#include "e10_frf.hpp"
#include "servotwin/io/plant_model_json.hpp"

namespace servotwin::cli_test {
namespace {

/// The last CSV row's cells.
std::vector<std::string> last_row(const std::string& csv) {
  std::istringstream in(csv);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream row(last);
  while (std::getline(row, cell, ',')) cells.push_back(cell);
  return cells;
}

TEST_F(Cli, SimulateRunsTheTunedControllerOnThePlantItWasTunedFrom) {
  ASSERT_EQ(run("tune table-5.1 -o pi.json").status, 0);
  const Result r = run("simulate --controller pi.json --duration 30 -o step.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("on table-5.1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("linear"), std::string::npos) << r.out;
  const std::string csv = slurp(path("step.csv"));
  EXPECT_EQ(csv.rfind("# servotwin.drive-simulation/1 test=step structure=pi ts=0.01", 0), 0U) << csv.substr(0, 80);
  // 30 s at ts = 10 ms: 3001 samples, a comment line and the header.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3003);
  // Closed form at the end: sliding at the reference 1 rad/s with Coulomb 0.5 N m on the load and
  // viscous bm + bl = 1.812431 + 1.787569 = 3.6 N m s/rad (flexible_presets.hpp): the torque
  // balances 0.5 + 3.6 = 4.1 N m; the linear part carries only the viscous 3.6 N m.
  const auto cells = last_row(csv);
  ASSERT_EQ(cells.size(), 14U);
  EXPECT_NEAR(std::stod(cells[3]), 4.1, 0.02);
  EXPECT_NEAR(std::stod(cells[5]), 1.0, 0.005);
  EXPECT_NEAR(std::stod(cells[9]), 3.6, 0.02);
}

TEST_F(Cli, TuneLqgAndSimulateIt) {
  // `tune --structure lqg` writes the compensator; `simulate` runs it on the preset with its
  // friction: the integral state balances the same 0.5 + 3.6 = 4.1 N m as the PI above.
  const Result t = run("tune table-5.1 --structure lqg -o lqg.json --report lqg.html");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("structure lqg: LQG velocity loop (C7.13, 5 states): kbw = "), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("compensator: "), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("verified by simulation"), std::string::npos) << t.out;
  EXPECT_NE(slurp(path("lqg.html")).find("LQG design (C7.13"), std::string::npos);
  const Result r = run("simulate --controller lqg.json --duration 30 -o step.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv = slurp(path("step.csv"));
  EXPECT_EQ(csv.rfind("# servotwin.drive-simulation/1 test=step structure=lqg", 0), 0U) << csv.substr(0, 80);
  const auto cells = last_row(csv);
  ASSERT_EQ(cells.size(), 14U);
  EXPECT_NEAR(std::stod(cells[3]), 4.1, 0.02);
  EXPECT_NEAR(std::stod(cells[5]), 1.0, 0.005);
}

TEST_F(Cli, TuneHinfAndSimulateIt) {
  // `tune --structure hinf` (C7.14) writes the controller: 10 states (8 of the weighted plant, one
  // of the preset's lag designed with, one integrator K = K0/s), 6 in its minimal realization (W2's
  // 4 poles cancel: C7.14's 5th order plus the lag); `simulate` runs it on the preset
  // with its friction: the integral action balances the same 0.5 + 3.6 = 4.1 N m.
  const Result t = run("tune table-5.1 --structure hinf -o hinf.json --report hinf.html");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("structure hinf: mixed-sensitivity velocity loop (C7.14, 6 states): w0S = "), std::string::npos)
      << t.out;
  EXPECT_NE(t.out.find("controller order: 6 of 10 (minimal realization)"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("gamma = "), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("verified by simulation"), std::string::npos) << t.out;
  EXPECT_NE(slurp(path("hinf.html")).find("H∞ mixed-sensitivity design (C7.14"), std::string::npos);
  const std::string json = slurp(path("hinf.json"));
  EXPECT_NE(json.find("\"gamma_optimal\""), std::string::npos);
  const Result r = run("simulate --controller hinf.json --duration 30 -o step.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv = slurp(path("step.csv"));
  EXPECT_EQ(csv.rfind("# servotwin.drive-simulation/1 test=step structure=hinf", 0), 0U) << csv.substr(0, 80);
  const auto cells = last_row(csv);
  ASSERT_EQ(cells.size(), 14U);
  EXPECT_NEAR(std::stod(cells[3]), 4.1, 0.02);
  EXPECT_NEAR(std::stod(cells[5]), 1.0, 0.005);
}

TEST_F(Cli, TuneLqgPlusPAndSimulateAPositionStep) {
  // C7.13's cascade alternative: a P position loop over the LQG velocity loop. The position step on
  // table-5.1: the motor reaches the target (integral action in the velocity loop; the load sticks
  // short of it on its stiction, as with pi+p in the study), and the file carries Kpp.
  const Result t = run("tune table-5.1 --structure lqg+p -o lqgp.json");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("structure lqg+p: LQG velocity loop"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("position loop: Kpp = "), std::string::npos) << t.out;
  const std::string json = slurp(path("lqgp.json"));
  EXPECT_NE(json.find("\"loop\": \"position\""), std::string::npos);
  EXPECT_NE(json.find("\"kpp_normalized\""), std::string::npos);
  const Result r = run("simulate --controller lqgp.json --duration 60 -o pos.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("controlled variable: load position"), std::string::npos) << r.out;
  const auto cells = last_row(slurp(path("pos.csv")));
  ASSERT_EQ(cells.size(), 14U);
  EXPECT_NEAR(std::stod(cells[6]), 1.0, 0.01);  // motor position at the target
}

TEST_F(Cli, TuneTheFullPositionLqgAndSimulateAPositionStep) {
  // C7.13's full-order position LQG (inputs [φ*, φm], its prefilter in front): the summary judges
  // positions, the file names position inputs, and the simulated step brings the motor to the
  // target (integral action on the motor position).
  const Result t = run("tune table-5.1 --structure lqg-pos -o lqgpos.json");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("structure lqg-pos: LQG position loop"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("reference prefilter: 1/(tau s + 1), tau = "), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("positions): stable"), std::string::npos) << t.out;
  const std::string json = slurp(path("lqgpos.json"));
  EXPECT_NE(json.find("\"position_reference\""), std::string::npos);
  EXPECT_NE(json.find("\"prefilter_tau\""), std::string::npos);
  const Result r = run("simulate --controller lqgpos.json --duration 60 -o pos.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("lqg-pos controller"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("controlled variable: load position"), std::string::npos) << r.out;
  const auto cells = last_row(slurp(path("pos.csv")));
  ASSERT_EQ(cells.size(), 14U);
  // The linear twin at the target; on the plant the load sticks beyond it on its stiction and the
  // motor creeps back against the shaft (within 2 % after 60 s).
  EXPECT_NEAR(std::stod(cells[12]), 1.0, 1e-3);
  EXPECT_NEAR(std::stod(cells[6]), 1.0, 0.02);
  const Result frame = run("simulate --controller lqgpos.json --plant c7.19-frame --test frame-sequence -o f.csv");
  EXPECT_NE(frame.status, 0);
  EXPECT_NE(frame.err.find("closes a position loop"), std::string::npos) << frame.err;
}

TEST_F(Cli, TuneTheLoadMeasuringControllersAndSimulateThem) {
  // C7.17: the load velocity measured (hinf-load), or both velocities (lqg-load). The tuner names
  // the design, the file says what is fed back, and simulate moves the preset's encoder to the
  // load (hinf-load) or adds a load encoder (lqg-load) and reaches ω*.
  struct Case {
    const char* structure;
    const char* summary;
    const char* feedback;
    const char* simulation_note;
  };
  for (const Case c : {Case{"hinf-load", "velocity, load measured loop (C7.17", "\"feedback\": \"load\"",
                            "moved from motor_velocity to load_velocity"},
                       Case{"lqg-load", "LQG velocity loop (C7.17, integral on the load, motor and load velocity measured",
                            "\"feedback\": \"both\"", "a second encoder of the same resolution (no noise) the load side"}}) {
    SCOPED_TRACE(c.structure);
    const std::string file = std::string(c.structure) + ".json", csv = std::string(c.structure) + ".csv";
    const Result t = run("tune table-5.1 --structure " + std::string(c.structure) + " -o " + file);
    ASSERT_EQ(t.status, 0) << t.err;
    EXPECT_NE(t.out.find(c.summary), std::string::npos) << t.out;
    EXPECT_NE(slurp(path(file)).find(c.feedback), std::string::npos);
    const Result r = run("simulate --controller " + file + " --duration 20 -o " + csv);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find(c.simulation_note), std::string::npos) << r.out;
    const auto cells = last_row(slurp(path(csv)));
    ASSERT_EQ(cells.size(), 14U);
    EXPECT_NEAR(std::stod(cells[5]), 1.0, 0.01);  // load velocity at the reference
    const Result compare = run("tune compare table-5.1 --structures pi," + std::string(c.structure));
    EXPECT_NE(compare.status, 0);
  }
}

TEST_F(Cli, SimulateLoadStepWithATorqueLimit) {
  ASSERT_EQ(run("tune table-5.1 -o pi.json").status, 0);
  const Result r = run("simulate --plant table-5.1 --controller pi.json --test load-step --amplitude 4 "
                       "--torque-limit 5 --duration 40 -o load.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("peak deviation"), std::string::npos) << r.out;
  // A load torque of 4 N m above the load's stiction 3 N m: at rest again the motor holds it
  // against the Coulomb level, |u| within the limit everywhere.
  std::istringstream in(slurp(path("load.csv")));
  std::string line;
  std::getline(in, line);
  std::getline(in, line);
  double peak = 0.0;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string cell;
    for (int c = 0; c < 4; ++c) std::getline(row, cell, ',');
    peak = std::max(peak, std::abs(std::stod(cell)));
  }
  EXPECT_LE(peak, 5.0);
}

TEST_F(Cli, SimulateExplainsWhatItCannotRun) {
  write("frf.csv", e10_csv(40));
  ASSERT_EQ(run("fit frf.csv --model two-mass -o pm.json").status, 0);
  ASSERT_EQ(run("tune pm.json -o pi.json").status, 0);
  Result r = run("simulate --controller pi.json");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("--plant"), std::string::npos) << r.err;
  write("tf.json", R"({"format": "servotwin.plant/1", "type": "transfer-function", "num": [1, 0.02, 1],
                       "den": [1, 0.18, 9, 0], "noise_std": 0, "ts": 0.01})");
  r = run("simulate --plant tf.json --controller pi.json --test load-step");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("load-torque input"), std::string::npos) << r.err;
  r = run("simulate --plant table-5.1 --controller pi.json --amplitude -1");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("amplitude"), std::string::npos) << r.err;
  EXPECT_EQ(run("simulate --plant table-5.1 --controller pi.json --test ramp").status, 2);
  ASSERT_EQ(run("simulate --plant table-5.1 --controller pi.json --duration 1 -o s.csv").status, 0);
  r = run("simulate --plant table-5.1 --controller pi.json --duration 1 -o s.csv");
  EXPECT_EQ(r.status, 3);  // never replaces an existing file without --force
}

}  // namespace
}  // namespace servotwin::cli_test

namespace servotwin::cli_test {
namespace {

// Issue 25 §7: measure -> fit -> tune -> simulate on files. The fitted model is simulated through
// its transfer-function realization; the closed form of the steady state is the model's own:
// holding 1 rad/s takes the torque 1/P(0).
TEST_F(Cli, SimulateRunsOnAFittedPlantModel) {
  ASSERT_EQ(run("frf measure --plant motor-bench -o mb.csv").status, 0);
  ASSERT_EQ(run("fit mb.csv -o mb.json").status, 0);
  ASSERT_EQ(run("tune mb.json -o pi.json").status, 0);
  Result r = run("simulate --controller pi.json -o step.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("(--ts): the plant is a fitted model (mb.json)"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("step.csv")));
  r = run("simulate --controller pi.json --ts 0.000125 --duration 2 -o step.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("pi controller on mb.json (ts = 0.000125 s"), std::string::npos) << r.out;
  const auto model = servotwin::io::load_plant_model(path("mb.json").string()).model;
  const auto cells = last_row(slurp(path("step.csv")));
  EXPECT_NEAR(std::stod(cells[3]), 1.0 / model.response(0.0).real(), 1e-6);
  EXPECT_NEAR(std::stod(cells[4]), 1.0, 1e-9);
  // Tuned at the drive's period, the controller carries it.
  ASSERT_EQ(run("tune mb.json --ts 0.000125 -o pid.json").status, 0);
  r = run("simulate --controller pid.json --duration 0.5");
  EXPECT_EQ(r.status, 0) << r.err;
}

}  // namespace
}  // namespace servotwin::cli_test
