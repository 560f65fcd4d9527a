// End-to-end tests of the servotwin binary: the exact command forms of the README and issue,
// exit statuses (0 success, 2 usage, 3 bad input), and that failed runs write nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <sys/wait.h>

#include "cli_support.hpp"

namespace {

using servotwin::cli_test::Cli;
using servotwin::cli_test::slurp;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

TEST_F(Cli, HelpListsCommandsAndEveryCommandHasExamples) {
  const auto top = run("--help");
  EXPECT_EQ(top.status, 0);
  for (const char* c : {"gcode", "interpolate", "capture", "machine", "demo"}) EXPECT_THAT(top.out, HasSubstr(c));
  for (const char* c : {"gcode", "gcode identification", "gcode contour", "gcode check", "gcode convert", "interpolate", "capture", "import", "identify", "solve", "model", "predict", "machine", "demo"}) {
    SCOPED_TRACE(c);
    const auto r = run(std::string(c) + " --help");
    EXPECT_EQ(r.status, 0);
    EXPECT_THAT(r.out, HasSubstr("Examples:"));
  }
}

TEST_F(Cli, UsageErrorsExitWithStatus2) {
  EXPECT_EQ(run("").status, 2);
  EXPECT_EQ(run("frobnicate").status, 2);
  EXPECT_EQ(run("gcode identification --moves -3").status, 2);
  EXPECT_EQ(run("interpolate --ts 0.001").status, 2);  // --program missing
  EXPECT_EQ(run("gcode identification --speed medium").status, 2);
}

TEST_F(Cli, IssueCommandFormsWork) {
  auto r = run("gcode identification --axis X --moves 200 --range 10 --feed 12000 --seed 7 -o id.nc");
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("gcode identification --axis X --dialect heidenhain --speed low --seed 7 -o low.h");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(slurp(path("low.h")), HasSubstr("BEGIN PGM"));
  r = run("interpolate --program id.nc --ts 0.001 --accel 2000 -o trajectory.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string trajectory = slurp(path("trajectory.csv"));
  EXPECT_EQ(trajectory.substr(0, trajectory.find('\n')), "t,x_cmd");
  r = run("capture --machine fadal-pid --program id.nc -o capture.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string capture = slurp(path("capture.csv"));
  EXPECT_EQ(capture.substr(0, capture.find('\n')), "t,x_cmd,x_act,x_u,y_cmd,y_act,y_u");
  // Same number of samples as the program interpolated with the machine's CNC settings. The
  // program states G61 (exact stop after every block), as the Fadal presets run anyway, so the
  // plain trajectory above has that length too; a program that states no mode runs on through
  // the joins of moves in the same direction (1 degree corner rule) and is shorter.
  ASSERT_EQ(run("interpolate --program id.nc --machine fadal-pid -o on-machine.csv").status, 0);
  const std::string on_machine = slurp(path("on-machine.csv"));
  EXPECT_EQ(std::count(capture.begin(), capture.end(), '\n'), std::count(on_machine.begin(), on_machine.end(), '\n'));
  EXPECT_EQ(std::count(trajectory.begin(), trajectory.end(), '\n'), std::count(on_machine.begin(), on_machine.end(), '\n'));
  ASSERT_EQ(run("gcode identification --axis X --moves 200 --range 10 --feed 12000 --seed 7 --path-mode unstated -o "
                "free.nc").status, 0);
  ASSERT_EQ(run("interpolate --program free.nc --ts 0.001 --accel 2000 -o free.csv").status, 0);
  const std::string free = slurp(path("free.csv"));
  EXPECT_LT(std::count(free.begin(), free.end(), '\n'), std::count(on_machine.begin(), on_machine.end(), '\n'));
  r = run("capture --machine fadal-pid --program low.h -o low.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("machine fadal-pid --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto report = nlohmann::json::parse(r.out);
  ASSERT_EQ(report["axes"].size(), 2U);
  for (const char* k : {"a1", "a2", "a3", "b0", "b1", "b2", "d0", "d1"}) EXPECT_TRUE(report["axes"][1]["closed_loop"].contains(k));
  EXPECT_NEAR(report["axes"][1]["closed_loop"]["a2"].get<double>(), 41031.98, 0.005);  // thesis Table 3.4, Y
  EXPECT_TRUE(report["axes"][0]["poles"][0].contains("hz"));
  EXPECT_TRUE(report["axes"][0]["poles"][0].contains("zeta"));
}

TEST_F(Cli, SameSeedSameProgramOtherSeedOtherProgram) {
  ASSERT_EQ(run("gcode identification --seed 7 -o a.nc").status, 0);
  ASSERT_EQ(run("gcode identification --seed 7 -o b.nc").status, 0);
  ASSERT_EQ(run("gcode identification --seed 8 -o c.nc").status, 0);
  EXPECT_EQ(slurp(path("a.nc")), slurp(path("b.nc")));
  EXPECT_NE(slurp(path("a.nc")), slurp(path("c.nc")));
}

TEST_F(Cli, BadInputExitsWith3AndWritesNothing) {
  write("bad.nc", "N10 G01 X10 F1000\nN20 G01 X20 Q7\n");
  auto r = run("interpolate --program bad.nc -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("bad.nc:2:"));
  EXPECT_THAT(r.err, HasSubstr("Q7"));
  EXPECT_FALSE(fs::exists(path("out.csv")));

  write("nofeed.nc", "G01 X10\n");
  r = run("capture --machine fadal-pid --program nofeed.nc -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_FALSE(fs::exists(path("out.csv")));

  write("arc.nc", "G01 X0 Y0 F1000\nG02 X10 Y0 I3 J0\n");  // radius 3 at start, 7 at the end
  r = run("interpolate --program arc.nc -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("arc.nc:2"));

  write("z.nc", "G01 Z5 F1000\n");
  r = run("capture --machine fadal-pid --program z.nc -o out.csv");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("axis Z"));

  r = run("machine no-such-machine");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("fadal-pid"));

  write("m.json", R"({"format": "servotwin.machine/1", "ts": 0.001, "axes": []})");
  r = run("machine m.json");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("m.json (axes)"));
  EXPECT_FALSE(fs::exists(path("out.csv")));
}

TEST_F(Cli, LenientTurnsUnknownWordsIntoWarnings) {
  write("q.nc", "G01 X10 F1000 Q7\n");
  EXPECT_EQ(run("gcode check q.nc").status, 3);
  const auto r = run("gcode check q.nc --lenient");
  EXPECT_EQ(r.status, 0);
  EXPECT_THAT(r.err, HasSubstr("q.nc:1:15: warning"));
}

TEST_F(Cli, ExistingOutputIsNotOverwrittenWithoutForce) {
  write("id.nc", "keep me\n");
  auto r = run("gcode identification -o id.nc");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("--force"));
  EXPECT_EQ(slurp(path("id.nc")), "keep me\n");
  r = run("gcode identification -o id.nc --force");
  EXPECT_EQ(r.status, 0);
  EXPECT_THAT(slurp(path("id.nc")), HasSubstr("G01"));
}

TEST_F(Cli, MachineListAndExportRoundTrip) {
  auto r = run("machine --list");
  ASSERT_EQ(r.status, 0);
  for (const char* name : {"fadal-ppi", "fadal-pid", "fadal-smc", "ballscrew-zpetc"}) EXPECT_THAT(r.out, HasSubstr(name));
  ASSERT_EQ(run("machine fadal-smc --export -o smc.json").status, 0);
  r = run("machine smc.json --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto from_file = nlohmann::json::parse(r.out);
  const auto from_preset = nlohmann::json::parse(run("machine fadal-smc --json").out);
  EXPECT_EQ(from_file["axes"], from_preset["axes"]);
}

TEST_F(Cli, DemoRunsOnTheBuiltInMachine) {
  const auto r = run("demo --out run");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("identification program"));
  EXPECT_THAT(r.out, HasSubstr("tracking error rms"));
  EXPECT_TRUE(fs::exists(path("run/capture.csv")));
  EXPECT_TRUE(fs::exists(path("run/identification.nc")));
}

TEST_F(Cli, ImportsTheEmpsBenchmarkWithMapAndScale) {
  const std::string emps = SERVOTWIN_REPO_DATA_DIR "/emps/DATA_EMPS.csv";
  auto r = run("import '" + emps + "' --map x_cmd=qg --map x_act=qm --map x_u=vir --scale 1000 -o emps.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("24841 samples at ts = 0.001"));  // data/emps/README.md
  const std::string rewritten = slurp(path("emps.csv"));
  EXPECT_EQ(rewritten.substr(0, rewritten.find('\n')), "t,x_cmd,x_act,x_u");
  // The rewritten file reads back as our own format without options.
  r = run("import emps.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("24841 samples"));
  // Without the map the reader says which columns exist and how to map them.
  r = run("import '" + emps + "'");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("columns: t, qm, qg, vir"));
  EXPECT_EQ(run("import '" + emps + "' --map x_cmd").status, 3);
}

TEST_F(Cli, ConvertsBetweenDialects) {
  ASSERT_EQ(run("gcode identification --speed high --dialect heidenhain --seed 3 -o high.h").status, 0);
  ASSERT_EQ(run("gcode convert high.h --to iso -o high.nc").status, 0);
  ASSERT_EQ(run("interpolate --program high.h -o a.csv").status, 0);
  ASSERT_EQ(run("interpolate --program high.nc -o b.csv").status, 0);
  EXPECT_EQ(slurp(path("a.csv")), slurp(path("b.csv")));
}

}  // namespace
