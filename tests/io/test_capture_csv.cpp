// Capture CSV reading and writing. Expected values come from the files themselves (the EMPS
// README gives sample count, period and first rows) or from the synthetic input built in the test.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/io/capture_csv.hpp"

namespace {

using servotwin::core::InputError;
using servotwin::io::CaptureReadOptions;
using servotwin::io::read_capture_csv;
using ::testing::HasSubstr;

std::string error_of(const std::string& text, const CaptureReadOptions& options = {}) {
  std::istringstream in(text);
  try {
    read_capture_csv(in, "cap.csv", options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

servotwin::core::Capture read(const std::string& text, const CaptureReadOptions& options = {}) {
  std::istringstream in(text);
  return read_capture_csv(in, "cap.csv", options);
}

TEST(CaptureCsv, ReadsOwnFormatWithCommentsAndOptionalU) {
  const auto c = read(
      "# servotwin capture\n"
      "t,x_cmd,x_act,x_u,y_cmd,y_act\n"
      "0.000,1,0.5,0.1,2,1.5\n"
      "\n"
      "# a comment in between\n"
      "0.001,1.25,0.75,-0.2,+2.5,2.25\n"
      "0.002,1.5,1.0,0.3,3.0,2.75\n");
  ASSERT_EQ(c.axes.size(), 2U);
  EXPECT_EQ(c.axes[0].name, "x");
  EXPECT_EQ(c.axes[1].name, "y");
  EXPECT_EQ(c.size(), 3U);
  EXPECT_DOUBLE_EQ(c.ts, 0.001);
  EXPECT_DOUBLE_EQ(c.t0, 0.0);
  EXPECT_EQ(c.axes[0].u, (std::vector<double>{0.1, -0.2, 0.3}));
  EXPECT_TRUE(c.axes[1].u.empty());
  EXPECT_EQ(c.axes[1].cmd, (std::vector<double>{2.0, 2.5, 3.0}));
}

TEST(CaptureCsv, WriteThenReadIsExact) {
  servotwin::core::Capture c;
  c.t0 = 0.5;
  c.ts = 0.0006;  // Heidenhain TNC 430 scope period (thesis section 4.3.3)
  servotwin::core::AxisTrace x{"x", {}, {}, {}};
  for (int k = 0; k < 500; ++k) {
    x.cmd.push_back(std::sin(0.01 * k) * 10.0 / 3.0);
    x.act.push_back(std::cos(0.013 * k) * 1e-7 + 1.0 / 7.0);
    x.u.push_back(-1e-300 * k);
  }
  c.axes.push_back(x);
  std::stringstream s;
  servotwin::io::write_capture_csv(s, c);
  const auto back = read_capture_csv(s, "roundtrip");
  ASSERT_EQ(back.size(), 500U);
  EXPECT_EQ(back.axes[0].cmd, x.cmd);
  EXPECT_EQ(back.axes[0].act, x.act);
  EXPECT_EQ(back.axes[0].u, x.u);
  EXPECT_NEAR(back.ts, c.ts, 1e-15);
  EXPECT_NEAR(back.t0, c.t0, 1e-15);
}

/// A stream that hides its size (no seeking), as a pipe does.
class UnseekableBuffer : public std::stringbuf {
 public:
  using std::stringbuf::stringbuf;

 protected:
  pos_type seekoff(off_type, std::ios_base::seekdir, std::ios_base::openmode) override { return pos_type(-1); }
  pos_type seekpos(pos_type, std::ios_base::openmode) override { return pos_type(-1); }
};

TEST(CaptureCsv, LongCapturesReadAcrossBlocksFromFilesAndPipes) {
  // The reader cuts lines from 1 MiB blocks and reserves the columns from the first rows' length
  // (issue 26). 60 000 rows (~4 MB): lines cross block boundaries, the last line has no line
  // break, one comment line is longer than a block, and row lengths change along the file (the
  // estimate from the first rows is then wrong and the columns grow as before). Read from a
  // seekable stream and from one that hides its size; both give the written numbers exactly.
  servotwin::core::Capture c;
  c.t0 = 0.0;
  c.ts = 0.001;
  servotwin::core::AxisTrace x{"x", {}, {}, {}};
  for (int k = 0; k < 60000; ++k) {
    x.cmd.push_back(k < 1000 ? 0.0 : std::sin(1e-3 * k) / 3.0);  // short rows first, then long ones
    x.act.push_back(k < 1000 ? 0.0 : std::cos(1.1e-3 * k) / 7.0);
  }
  c.axes.push_back(x);
  std::stringstream written;
  servotwin::io::write_capture_csv(written, c);
  std::string text = written.str();
  text.pop_back();  // no line break after the last row
  const std::size_t header_end = text.find('\n') + 1;
  text.insert(header_end, "# " + std::string((1u << 20) + 100, 'c') + "\n");
  std::istringstream seekable(text);
  UnseekableBuffer buffer(text);
  std::istream unseekable(&buffer);
  for (std::istream* in : {static_cast<std::istream*>(&seekable), &unseekable}) {
    const auto back = read_capture_csv(*in, "long.csv");
    ASSERT_EQ(back.size(), 60000U);
    EXPECT_EQ(back.axes[0].cmd, x.cmd);
    EXPECT_EQ(back.axes[0].act, x.act);
    EXPECT_NEAR(back.ts, 0.001, 1e-15);
  }
  // An error far into the file still names its line: 1 header + 1 comment + row 50001.
  std::string bad = text;
  std::size_t line_start = header_end;
  for (int row = 0; row < 50001; ++row) line_start = bad.find('\n', line_start) + 1;
  bad.insert(bad.find(',', line_start) + 1, "x");
  EXPECT_THAT(error_of(bad), HasSubstr("cap.csv:50003:"));
}

/// A capture text with the given time stamps and x_cmd = x_act = row number.
std::string with_times(const std::vector<double>& t) {
  std::string text = "t,x_cmd,x_act\n";
  char field[32];
  for (std::size_t k = 0; k < t.size(); ++k) {
    const auto r = std::to_chars(field, field + sizeof field, t[k]);
    text.append(field, r.ptr);
    text += "," + std::to_string(k) + "," + std::to_string(k) + "\n";
  }
  return text;
}

/// The grid the reader must find: t0 = t[0], ts = (t[n-1] - t[0]) / (n - 1), computed here from
/// the doubles written (std::to_chars round-trips them exactly).
void expect_grid(const servotwin::core::Capture& c, const std::vector<double>& t) {
  EXPECT_EQ(c.t0, t.front());
  EXPECT_EQ(c.ts, (t.back() - t.front()) / static_cast<double>(t.size() - 1));
}

TEST(CaptureCsv, TimeStampsKeepTheirGridAndFirstOffGridRowInEveryForm) {
  // The reader keeps the time column as steps numbered in a dictionary (issue 26: two bytes a row)
  // and falls back to doubles when a step does not give back the stamp exactly (times across
  // zero) or when there are more than 65 536 distinct steps (random jitter). In every form the
  // grid is the one computed from the stamps, and the first off-grid row is the one reported.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);  // below the default 1 %
  const std::size_t n = 100000;
  std::vector<std::vector<double>> cases(3, std::vector<double>(n));
  for (std::size_t k = 0; k < n; ++k) {
    cases[0][k] = 100.0 + 0.001 * static_cast<double>(k);                            // decimal steps
    cases[1][k] = -50.0 + 0.001 * static_cast<double>(k);                            // through zero
    cases[2][k] = 3.0 + 0.001 * (static_cast<double>(k) + jitter(rng));              // jittered
  }
  for (const auto& t : cases) {
    expect_grid(read(with_times(t)), t);
    // Row 70 000 off the grid by 3 %, row 80 000 by 5 %: the first is reported (line 70 002).
    std::vector<double> off = t;
    off[70000] += 0.00003;
    off[80000] += 0.00005;
    const std::string e = error_of(with_times(off));
    EXPECT_THAT(e, HasSubstr("cap.csv:70002"));
    EXPECT_THAT(e, HasSubstr("off the uniform grid"));
  }
}

TEST(CaptureCsv, TimeColumnPrintsWithoutNoiseDigits) {
  servotwin::core::Capture c;
  c.ts = 0.001;
  c.axes.push_back({"x", {0, 0, 0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0, 0, 0}, {}});
  std::stringstream s;
  servotwin::io::write_capture_csv(s, c);
  EXPECT_THAT(s.str(), HasSubstr("\n0.007,0,0\n"));  // not 0.007000000000000001
}

TEST(CaptureCsv, ReadsEmpsWithMappingAndScale) {
  CaptureReadOptions o;
  o.map = {{"x_cmd", "qg"}, {"x_act", "qm"}, {"x_u", "vir"}};
  o.scale = 1000.0;  // metres -> mm
  const auto c = servotwin::io::read_capture_file(SERVOTWIN_REPO_DATA_DIR "/emps/DATA_EMPS.csv", o);
  ASSERT_EQ(c.axes.size(), 1U);
  EXPECT_EQ(c.size(), 24841U);  // data/emps/README.md
  EXPECT_NEAR(c.ts, 0.001, 1e-8);
  // First data row of DATA_EMPS.csv: t=0, qm=7.4499999999999998e-06, qg=0.00010782208000001829, vir=2.5386280888756465
  EXPECT_DOUBLE_EQ(c.axes[0].cmd[0], 0.00010782208000001829 * 1000.0);
  EXPECT_DOUBLE_EQ(c.axes[0].act[0], 7.4499999999999998e-06 * 1000.0);
  EXPECT_DOUBLE_EQ(c.axes[0].u[0], 2.5386280888756465);  // u is not scaled
}

TEST(CaptureCsv, UnitScaleGivesTheSameDataInMm) {
  CaptureReadOptions m;
  m.map = {{"x_cmd", "qg"}, {"x_act", "qm"}};
  CaptureReadOptions mm = m;
  mm.scale = 1000.0;
  const auto in_m = servotwin::io::read_capture_file(SERVOTWIN_REPO_DATA_DIR "/emps/DATA_EMPS_PULSES.csv", m);
  const auto in_mm = servotwin::io::read_capture_file(SERVOTWIN_REPO_DATA_DIR "/emps/DATA_EMPS_PULSES.csv", mm);
  ASSERT_EQ(in_m.size(), in_mm.size());
  for (std::size_t k = 0; k < in_m.size(); k += 97) EXPECT_DOUBLE_EQ(in_mm.axes[0].act[k], 1000.0 * in_m.axes[0].act[k]);
}

TEST(CaptureCsv, AcceptsJitterBelowOnePercentAndRejectsMore) {
  EXPECT_NO_THROW(read("t,x_cmd,x_act\n0,0,0\n0.001005,1,1\n0.002,2,2\n0.002996,3,3\n"));
  const std::string e = error_of("t,x_cmd,x_act\n0,0,0\n0.001,1,1\n0.00203,2,2\n0.003,3,3\n");
  EXPECT_THAT(e, HasSubstr("cap.csv:4"));
  EXPECT_THAT(e, HasSubstr("off the uniform grid"));
}

TEST(CaptureCsv, RejectsNonIncreasingTime) {
  const std::string e = error_of("t,x_cmd,x_act\n0,0,0\n0.001,1,1\n0.001,2,2\n");
  EXPECT_THAT(e, HasSubstr("cap.csv:4:1"));
  EXPECT_THAT(e, HasSubstr("time does not increase"));
}

TEST(CaptureCsv, RejectsTextNanAndInfinityNamingLineColumnAndField) {
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n0.001,abc,1\n"), HasSubstr("cap.csv:3:7: column 'x_cmd': expected a number, found 'abc'"));
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,nan\n0.001,1,1\n"), HasSubstr("cap.csv:2:5: column 'x_act'"));
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n0.001,1,-inf\n"), HasSubstr("not finite"));
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n0.001,1,\n"), HasSubstr("empty value"));
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n0.001,1,1e999\n"), HasSubstr("out of range"));
}

// Found by fuzz_capture_csv: a finite value that overflows once scaled was stored as infinity.
TEST(CaptureCsv, RejectsValuesThatOverflowWhenScaled) {
  CaptureReadOptions o;
  o.scale = 1000.0;
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,7.5e306\n0.001,1,1\n", o), HasSubstr("cap.csv:2:5 (x_act): value times the scale 1000 overflows"));
}

TEST(CaptureCsv, RejectsMissingColumnsWithAHint) {
  const std::string e = error_of("t,qg,qm\n0,0,0\n0.001,1,1\n");
  EXPECT_THAT(e, HasSubstr("no axis columns"));
  EXPECT_THAT(e, HasSubstr("--map x_cmd=<column>"));
  EXPECT_THAT(error_of("t,x_cmd\n0,0\n0.001,1\n"), HasSubstr("missing column 'x_act'"));
  CaptureReadOptions o;
  o.map = {{"x_cmd", "nope"}};
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n0.001,1,1\n", o), HasSubstr("the file has no column 'nope'"));
  EXPECT_THAT(error_of("time,x_cmd,x_act\n0,0,0\n0.001,1,1\n"), HasSubstr("missing time column 't'"));
}

TEST(CaptureCsv, RejectsEmptyShortAndRaggedFiles) {
  EXPECT_THAT(error_of(""), HasSubstr("empty file"));
  EXPECT_THAT(error_of("# only a comment\n\n"), HasSubstr("empty file"));
  EXPECT_THAT(error_of("t,x_cmd,x_act\n"), HasSubstr("0 data rows"));
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n"), HasSubstr("1 data row:"));
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n0.001,1\n"), HasSubstr("cap.csv:3: expected 3 fields"));
  EXPECT_THAT(error_of("t,x_cmd,x_act,x_act\n0,0,0,0\n0.001,1,1,1\n"), HasSubstr("appears twice"));
}

TEST(CaptureCsv, UsesTsOptionWithoutTimeColumn) {
  CaptureReadOptions o;
  o.ts = 0.002;
  const auto c = read("x_cmd,x_act\n0,0\n1,1\n2,2\n", o);
  EXPECT_DOUBLE_EQ(c.ts, 0.002);
  o.ts = 0.0005;
  EXPECT_THAT(error_of("t,x_cmd,x_act\n0,0,0\n0.001,1,1\n", o), HasSubstr("disagrees"));
  o.ts = -1.0;
  EXPECT_THAT(error_of("x_cmd,x_act\n0,0\n1,1\n", o), HasSubstr("(--ts)"));
}

TEST(CaptureCsv, ParsesColumnMappings) {
  EXPECT_EQ(servotwin::io::parse_column_mapping("X_CMD=qg"), (std::pair<std::string, std::string>{"x_cmd", "qg"}));
  EXPECT_THROW(servotwin::io::parse_column_mapping("x_cmd"), InputError);
  EXPECT_THROW(servotwin::io::parse_column_mapping("=qg"), InputError);
  EXPECT_THROW(servotwin::io::parse_column_mapping("x_cmd="), InputError);
}

}  // namespace
