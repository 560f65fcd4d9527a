// Issue 27 §4: messages name what the user typed — the option rather than the library's parameter,
// the line where a problem is, the delimiter a file really uses — quote user text with its control
// bytes escaped, print lengths in the units of the report and spell plurals.
#include <gmock/gmock.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "cli_support.hpp"

namespace servotwin::cli_test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

class Messages : public Cli {
 protected:
  void SetUp() override {
    Cli::SetUp();
    write("a.nc", "G21 G90\nG01 X10 F600\nM30\n");
  }
  /// stderr of a run that must fail with `status`.
  std::string error_of(const std::string& args, int status = 3) const {
    const Result r = run(args);
    EXPECT_EQ(r.status, status) << args << ": " << r.err;
    return r.err;
  }
};

// The interpolator's limits were named by its fields: "(corner_angle_deg)", "(max_samples)",
// "(rapid_feed_mm_min)", and 1e-9 s printed as 0.000000.
TEST_F(Messages, InterpolationLimitsAreNamedByTheirOptions) {
  EXPECT_THAT(error_of("interpolate -p a.nc --corner-angle 200"), HasSubstr("(--corner-angle): must be in [0, 180] degrees, got 200"));
  EXPECT_THAT(error_of("interpolate -p a.nc --rapid-feed 0"), HasSubstr("(--rapid-feed): must be a finite value > 0, got 0"));
  EXPECT_THAT(error_of("interpolate -p a.nc --accel -5"), HasSubstr("(--accel)"));
  // Too many samples: the program is too long for the sample period, so the period is named.
  const std::string samples = error_of("interpolate -p a.nc --ts 1e-9");
  EXPECT_THAT(samples, HasSubstr("(--ts): the program would need more than"));
  EXPECT_THAT(samples, HasSubstr("at ts = 0.000000001 s"));
  // A limit that came from a machine file names the file and its field.
  ASSERT_EQ(run("machine fadal-pid --export -o m.json").status, 0);
  std::string machine = slurp(path("m.json"));
  const std::string ts_field = "\"ts\": 0.001";
  ASSERT_NE(machine.find(ts_field), std::string::npos) << machine;
  machine.replace(machine.find(ts_field), ts_field.size(), "\"ts\": 1e-9");
  write("tiny_ts.json", machine);
  EXPECT_THAT(error_of("interpolate -p a.nc -m tiny_ts.json"), HasSubstr("tiny_ts.json (ts): the program would need more than"));
  // predict samples at its models' period, whatever machine gave the other limits.
  ASSERT_EQ(run("demo --out d -q").status, 0);
  write("long.nc", "G21 G90\nG01 X10 F0.001\nM30\n");  // 6e5 s: 6e8 samples at the models' 1 ms
  EXPECT_THAT(error_of("predict --model d/model_x.json --program long.nc -m tiny_ts.json"),
              HasSubstr("d/model_x.json (ts): the program would need more than"));
  EXPECT_THAT(error_of("predict --model d/model_x.json --program a.nc --accel 0"), HasSubstr("(--accel)"));
}

// A gap in the time column was reported at line 3 (the first sample off the end-to-end grid).
TEST_F(Messages, ATimeGapIsReportedWhereItIs) {
  std::ostringstream csv;
  csv << "t,x_cmd,x_act\n";
  for (int k = 0; k < 40; ++k) {
    const double t = 0.001 * k + (k >= 30 ? 0.005 : 0.0);  // 5 samples missing before line 32
    csv << t << ',' << k << ',' << k << '\n';
  }
  write("gap.csv", csv.str());
  const std::string err = error_of("import gap.csv -o out.csv");
  EXPECT_THAT(err, HasSubstr("gap.csv:32 (t): time jumps from 0.029 to 0.035 s here, 6 steps of the trace's typical 0.001 s"));
  // Three rows: the gap is the wider of the two steps.
  write("three.csv", "t,x_cmd,x_act\n0,0,0\n0.001,1,1\n0.005,2,2\n");
  EXPECT_THAT(error_of("import three.csv -o out.csv"), HasSubstr("three.csv:4 (t): time jumps from 0.001 to 0.005 s here, 4 steps"));
  // A clock that drifts has no single step to blame: the first sample off the grid is named.
  std::ostringstream drift;
  drift << "t,x_cmd,x_act\n";
  for (int k = 0; k < 40; ++k) drift << 0.001 * k * (1.0 + 0.0004 * k) << ',' << k << ',' << k << '\n';
  write("drift.csv", drift.str());
  EXPECT_THAT(error_of("import drift.csv -o out.csv"), HasSubstr("off the uniform grid"));
}

// A ';'-separated file said "missing time column 't' (columns: t;x_cmd;x_act)".
TEST_F(Messages, AFileWithAnotherDelimiterSaysSo) {
  write("semi.csv", "t;x_cmd;x_act\n0;0;0\n0.001;1;1\n0.002;2;2\n");
  EXPECT_THAT(error_of("import semi.csv -o out.csv"),
              HasSubstr("semi.csv:1: the header is a single column 't;x_cmd;x_act': the file looks ';'-separated "
                        "(read it with --delimiter ';')"));
  write("tab.csv", "t\tx_cmd\tx_act\n0\t0\t0\n0.001\t1\t1\n0.002\t2\t2\n");
  EXPECT_THAT(error_of("import tab.csv -o out.csv"), HasSubstr("looks tab-separated (read it with --delimiter tab)"));
  EXPECT_EQ(run("import tab.csv --delimiter tab -o out.csv").status, 0);
  // The other way round: --delimiter ';' on a comma-separated file.
  write("comma.csv", "t,x_cmd,x_act\n0,0,0\n0.001,1,1\n0.002,2,2\n");
  EXPECT_THAT(error_of("import comma.csv --delimiter ';' -o out.csv"), HasSubstr("looks ','-separated (read it with --delimiter ',')"));
  // The signal reader has no delimiter setting.
  write("semi_signals.csv", "t;u;y\n0;0;0\n0.001;1;1\n");
  EXPECT_THAT(error_of("frf estimate semi_signals.csv --input u --response y -o f.csv"),
              HasSubstr("looks ';'-separated (save it comma-separated)"));
}

// Control bytes from a file or the command line reached the terminal (or became '?').
TEST_F(Messages, ControlBytesAreEscaped) {
  write("ctl.csv", "t,x_cmd,x_act\n0,0,0\n0.001,1\x01,1\n");
  const std::string csv = error_of("import ctl.csv -o out.csv");
  EXPECT_THAT(csv, HasSubstr("found '1\\x01'"));
  write("esc.nc", "G1 X1\x1b[2J F100\n");
  const std::string program = error_of("interpolate -p esc.nc");
  EXPECT_THAT(program, HasSubstr("'\\x1b'"));
  const std::string unknown = error_of("fro\x1b[2Jb", 2);
  EXPECT_THAT(unknown, HasSubstr("unknown subcommand 'fro\\x1b[2Jb'"));
  for (const std::string& err : {csv, program, unknown}) EXPECT_EQ(err.find('\x1b'), std::string::npos) << err;
}

// predict printed its errors in mm beside a report in µm; identify --scale 1000 printed "file unit
// x 1000"; counts were "2 axis(es)".
TEST_F(Messages, UnitsAndPlurals) {
  ASSERT_EQ(run("demo --out d -q").status, 0);
  Result r = run("predict --model d/model_x.json --model d/model_y.json --program d/circle.nc -o p.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("errors in µm"));
  EXPECT_THAT(r.err, HasSubstr("predicted 2 axes over"));
  // The printed maximum is the CSV's (mm) times 1000. CSV: t,x_cmd,x_pred,x_err,...
  std::istringstream csv(slurp(path("p.csv")));
  std::string line;
  std::getline(csv, line);
  double max_mm = 0.0;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream cells(line);
    std::string cell;
    for (int c = 0; c < 4; ++c) std::getline(cells, cell, ',');
    max_mm = std::max(max_mm, std::abs(std::stod(cell)));
  }
  const std::string printed = r.out.substr(r.out.find("axis x tracking error"));
  const std::size_t at = printed.find("max ") + 4;
  EXPECT_NEAR(std::stod(printed.substr(at)), 1000.0 * max_mm, 1e-3 * 1000.0 * max_mm) << printed;

  r = run("identify d/capture.csv --scale 1000 -o s_{axis}.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("mm (file in m, x 1000)"));
  EXPECT_THAT(r.out, Not(HasSubstr("file unit")));
  EXPECT_THAT(r.err, HasSubstr("read 1 capture in"));
  EXPECT_THAT(r.err, HasSubstr("identified 2 axes"));
  r = run("import d/capture.csv -o i.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(", 2 axes"));
}

// --shift auto chose a shift whose nrmse was not the lowest without saying why. On the demo's
// capture the y axis fits best at shift 1 (0.0374) and the rule keeps shift 0 (0.0376, within 2 %).
TEST_F(Messages, TheShiftRuleIsStatedWhenTheChoiceIsNotTheBestFit) {
  ASSERT_EQ(run("demo --out d -q").status, 0);
  const Result r = run("identify d/capture.csv --shift auto -o m_{axis}.json");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::size_t y = r.out.find("axis y:");
  ASSERT_NE(y, std::string::npos) << r.out;
  EXPECT_THAT(r.out.substr(y), HasSubstr("(the rule: of the stable models, the smallest |shift| whose nrmse is within 2 % of the best)"));
  EXPECT_THAT(r.out.substr(0, y), Not(HasSubstr("the rule:")));  // x: shift 0 is also the best fit
}

}  // namespace
}  // namespace servotwin::cli_test
