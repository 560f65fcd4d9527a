// End-to-end tests of reading controller traces from the command line: LinuxCNC halsampler output
// named by the HAL file and timed by the INI file (the integration rig's own, integration/linuxcnc/),
// halscope logs, profiles written by `import --save-profile` and read by --profile, the checks
// against the program a trace ran, and bad input (exit status 3, the file or option named).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "cli_support.hpp"

namespace {

using servotwin::cli_test::Cli;
using servotwin::cli_test::slurp;
using ::testing::HasSubstr;

const std::string kSamples = std::string(SERVOTWIN_REPO_DATA_DIR) + "/profiles/samples/";
const std::string kRig = std::string(SERVOTWIN_REPO_DATA_DIR) + "/../integration/linuxcnc/";
const std::string kRigTrace = kSamples + "linuxcnc-servotwin-rig.txt";
const std::string kLinuxCnc = " --hal " + kRig + "servotwin_sim.hal --ini " + kRig + "servotwin_sim.ini";

class ImportTraces : public Cli {};

TEST_F(ImportTraces, HalsamplerNamedByTheHalFileAndTimedByTheIni) {
  auto r = run("import " + kRigTrace + kLinuxCnc + " -o rig.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("halsampler (LinuxCNC), 300 samples at ts = 0.001 s"));
  EXPECT_THAT(r.out, HasSubstr("x: command 0.324333 .. 20"));
  EXPECT_THAT(r.out, HasSubstr("note: axis z: the command never moves"));
  EXPECT_THAT(slurp(path("rig.csv")), testing::StartsWith("t,x_cmd,x_act,x_u,y_cmd,y_act,y_u,z_cmd,z_act,z_u\n0.000,0.324333,0.156824,126.013391,"));
  // The reading saved as a profile reads the same trace alone.
  r = run("import " + kRigTrace + kLinuxCnc + " --save-profile rig.json --description 'the rig'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string profile = slurp(path("rig.json"));
  EXPECT_THAT(profile, HasSubstr("\"trace_format\": \"halsampler\""));
  EXPECT_THAT(profile, HasSubstr("\"ts\": 0.001"));
  r = run("import " + kRigTrace + " --profile rig.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("300 samples at ts = 0.001 s"));
  // halscope's layout of the same cycles, with the shipped profile.
  r = run("import " + kSamples + "linuxcnc-halscope.csv --profile " + kSamples + "../linuxcnc-halscope.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("halscope (LinuxCNC), 300 samples at ts = 0.001 s"));
  EXPECT_THAT(r.out, HasSubstr("x: command 0.324333 .. 20"));
}

TEST_F(ImportTraces, BadReadingOptionsNameTheOptionOrTheLine) {
  write("bad.json", R"({"format": "servotwin.trace-profile/1", "units": "yards"})");
  const std::string halsampler = " --format halsampler --ts 0.001 --columns x_cmd,x_act,x_u,y_cmd,y_act,y_u,z_cmd,z_act,z_u";
  // The file has 9 pins and a sample number: one name too many, two too many, none.
  const std::vector<std::pair<std::string, std::string>> cases{
      {halsampler + ",extra", "first column counts 1 by 1"},
      {halsampler + ",a,b", "fewer columns than pins"},
      {" --format halsampler --ts 0.001", "--columns"},
      {kLinuxCnc + " --columns x_cmd", "--columns or --hal, not both"},
      {kLinuxCnc + " --ts 0.002", "disagrees"},
      {" --profile bad.json", "bad.json"},
      {kLinuxCnc + " --delimiter ab", "--delimiter"}};
  for (const auto& [options, message] : cases) {
    const auto r = run("import " + kRigTrace + options);
    EXPECT_EQ(r.status, 3) << options;
    EXPECT_THAT(r.err, HasSubstr(message)) << options;
  }
}

TEST_F(ImportTraces, ATraceIsCheckedAgainstTheProgramItRan) {
  // The virtual machine runs the diamond; its capture in metres is a unit mismatch.
  ASSERT_EQ(run("gcode contour --shape diamond -o diamond.nc").status, 0);
  ASSERT_EQ(run("capture --machine fadal-pid --program diamond.nc -o run.csv").status, 0);
  auto r = run("import run.csv --program diamond.nc");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("keeps within"));
  r = run("import run.csv --program diamond.nc --scale 0.001");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("is the trace in m? read it with --scale 1000"));
  // A run with the feed override at 150 %: the program says F8000, the machine ran F12000.
  ASSERT_EQ(run("gcode contour --shape diamond --feed 8000 -o slow.nc").status, 0);
  r = run("import run.csv --program slow.nc");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: the commanded speed reaches 150 % of the programmed F8000"));
  // Another program entirely.
  ASSERT_EQ(run("gcode contour --shape circle -o circle.nc").status, 0);
  r = run("import run.csv --program circle.nc");
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("leaves circle.nc's path"));
}

}  // namespace
