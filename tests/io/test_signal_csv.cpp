// Signal CSV reader: time columns with units, explicit sample rate, and every bad-input case
// named by file, line, column and CSV column. Expected values are the literal file contents.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/io/signal_csv.hpp"

namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace signal_csv_test {

using servotwin::core::InputError;
using servotwin::io::read_signal_csv;
using servotwin::io::SignalReadOptions;
using servotwin::io::SignalTable;
using ::testing::HasSubstr;

SignalTable read(const std::string& text, const SignalReadOptions& o = {}) {
  std::istringstream in(text);
  return read_signal_csv(in, "rec.csv", o);
}

/// The error thrown for `text`, or a failure when none is.
InputError error_of(const std::string& text, const SignalReadOptions& o = {}) {
  try {
    read(text, o);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return InputError("none");
}

TEST(SignalCsv, TimeInMicrosecondsGivesTheExactPeriod) {
  const auto t = read("# bench run\ntime_us,u,y\n0,1,2\n400,1.5,2.5\n800,-1,3\n1200,0,4\n");
  EXPECT_EQ(t.ts, 0.0004);  // 400 / 1e6, not 400 * 1e-6
  EXPECT_EQ(t.t0, 0.0);
  EXPECT_EQ(t.time_column, "time_us");
  EXPECT_EQ(t.names, (std::vector<std::string>{"u", "y"}));
  EXPECT_EQ(t.column("u"), (std::vector<double>{1, 1.5, -1, 0}));
  EXPECT_EQ(t.column("y"), (std::vector<double>{2, 2.5, 3, 4}));
  EXPECT_EQ(t.size(), 4u);
}

TEST(SignalCsv, TimeColumnUnits) {
  EXPECT_EQ(servotwin::io::time_column_unit("t"), 1.0);
  EXPECT_EQ(servotwin::io::time_column_unit("Time"), 1.0);
  EXPECT_EQ(servotwin::io::time_column_unit("time_s"), 1.0);
  EXPECT_EQ(servotwin::io::time_column_unit("t_ms"), 1e-3);
  EXPECT_EQ(servotwin::io::time_column_unit("time_us"), 1e-6);
  EXPECT_EQ(servotwin::io::time_column_unit("time_ns"), 1e-9);
  EXPECT_FALSE(servotwin::io::time_column_unit("timestamp"));
  EXPECT_FALSE(servotwin::io::time_column_unit("time_min"));
  EXPECT_DOUBLE_EQ(read("t,a\n1.0,0\n1.001,1\n1.002,0\n").ts, 0.001);
  EXPECT_DOUBLE_EQ(read("t,a\n1.0,0\n1.001,1\n1.002,0\n").t0, 1.0);
  EXPECT_DOUBLE_EQ(read("time_ms,a\n0,0\n0.5,1\n1.0,0\n").ts, 0.0005);
}

TEST(SignalCsv, SampleRateWithoutTimeColumnAndSelectedColumns) {
  SignalReadOptions o;
  o.fs = 2500.0;
  o.columns = {"y", "u"};
  const auto t = read("u,y,z\n1,2,3\n4,5,6\n", o);
  EXPECT_EQ(t.ts, 1.0 / 2500.0);
  EXPECT_EQ(t.names, (std::vector<std::string>{"y", "u"}));
  EXPECT_EQ(t.column("y"), (std::vector<double>{2, 5}));
  EXPECT_TRUE(t.time_column.empty());
  // fs agreeing with the time column is accepted; disagreeing is not.
  o.columns = {};
  o.fs = 1000.0;
  EXPECT_DOUBLE_EQ(read("t,a\n0,1\n0.001,2\n", o).ts, 0.001);
  o.fs = 2000.0;
  const auto e = error_of("t,a\n0,1\n0.001,2\n", o);
  EXPECT_EQ(e.where().field, "--fs");
  EXPECT_THAT(e.what(), HasSubstr("disagrees with the time column 't' (1000 Hz)"));
}

TEST(SignalCsv, ExplicitTimeColumnMustCarryItsUnit) {
  SignalReadOptions o;
  o.time_column = "time_us";
  EXPECT_EQ(read("time_us,t,a\n0,5,1\n10,5,2\n", o).ts, 1e-5);
  o.time_column = "stamp";
  EXPECT_THAT(error_of("stamp,a\n0,1\n1,2\n", o).what(), HasSubstr("unit must be in its name"));
  o.time_column = "clock";
  const auto e = error_of("stamp,a\n0,1\n1,2\n", o);
  EXPECT_THAT(e.what(), HasSubstr("missing time column 'clock' (columns: stamp, a)"));
}

TEST(SignalCsv, NonUniformSamplingNamesTheLine) {
  // Line 5 (time 0.0035) breaks the 1 ms grid.
  const auto e = error_of("t,u\n0,1\n0.001,2\n0.002,3\n0.0035,4\n0.004,5\n0.005,6\n");
  EXPECT_EQ(e.where().file, "rec.csv");
  EXPECT_EQ(e.where().line, 5u);
  EXPECT_EQ(e.where().field, "t");
  EXPECT_THAT(e.what(), HasSubstr("non-uniform sampling"));
  // A step within the jitter tolerance is accepted.
  EXPECT_NO_THROW(read("t,u\n0,1\n0.001,2\n0.002005,3\n0.003,4\n"));
}

TEST(SignalCsv, TimeThatDoesNotIncreaseNamesLineAndColumn) {
  const auto e = error_of("a,t\n1,0\n2,0.001\n3,0.001\n");
  EXPECT_EQ(e.where().line, 4u);
  EXPECT_EQ(e.where().column, 3u);
  EXPECT_THAT(e.what(), HasSubstr("time does not increase"));
}

TEST(SignalCsv, NanAndTextAreRejectedAtTheirField) {
  auto e = error_of("t,u,y\n0,1,2\n0.1,nan,2\n");
  EXPECT_EQ(e.where().line, 3u);
  EXPECT_EQ(e.where().column, 5u);
  EXPECT_THAT(e.what(), HasSubstr("column 'u'"));
  e = error_of("t,u,y\n0,1,2\n0.1,1,abc\n");
  EXPECT_EQ(e.where().column, 7u);
  EXPECT_THAT(e.what(), HasSubstr("expected a number, found 'abc'"));
  e = error_of("t,u,y\n0,1,2\n0.1,inf,2\n");
  EXPECT_THAT(e.what(), HasSubstr("not finite"));
}

TEST(SignalCsv, MissingColumnsListTheAvailableOnes) {
  SignalReadOptions o;
  o.columns = {"iq", "theta"};
  const auto e = error_of("time_us,iq_adx,theta_mx\n0,1,2\n400,1,2\n", o);
  EXPECT_EQ(e.where().field, "iq");
  EXPECT_THAT(e.what(), HasSubstr("missing column 'iq' (columns: time_us, iq_adx, theta_mx)"));
  const auto t = read("t,a\n0,1\n1,2\n");
  try {
    (void)t.column("b");
    ADD_FAILURE();
  } catch (const InputError& err) {
    EXPECT_THAT(err.what(), HasSubstr("missing column 'b' (columns: t, a)"));
  }
}

TEST(SignalCsv, NoTimeColumnAndNoRateIsAnError) {
  const auto e = error_of("u,y\n1,2\n3,4\n");
  EXPECT_EQ(e.where().line, 1u);
  EXPECT_THAT(e.what(), HasSubstr("no time column"));
  EXPECT_THAT(e.what(), HasSubstr("columns: u, y"));
  EXPECT_THAT(e.what(), HasSubstr("--fs"));
}

TEST(SignalCsv, StructuralErrors) {
  EXPECT_THAT(error_of("").what(), HasSubstr("empty file"));
  EXPECT_THAT(error_of("# only a comment\n\n").what(), HasSubstr("empty file"));
  auto e = error_of("t,u\n0,1\n0.1\n");
  EXPECT_EQ(e.where().line, 3u);
  EXPECT_THAT(e.what(), HasSubstr("expected 2 fields as in the header, found 1"));
  e = error_of("t,u\n0,1\n");
  EXPECT_THAT(e.what(), HasSubstr("1 data row: a time series needs at least 2 samples"));
  e = error_of("t,u,u\n0,1,1\n1,1,1\n");
  EXPECT_EQ(e.where().column, 5u);
  EXPECT_THAT(e.what(), HasSubstr("appears twice"));
  e = error_of("t,,u\n0,1,1\n1,1,1\n");
  EXPECT_THAT(e.what(), HasSubstr("empty column name"));
  SignalReadOptions o;
  o.fs = -1.0;
  EXPECT_EQ(error_of("t,u\n0,1\n1,2\n", o).where().field, "--fs");
}

TEST(SignalCsv, ConstantExcitationColumnIsRejected) {
  const auto t = read("t,u,y\n0,2.5,1\n1,2.5,2\n2,2.5,3\n");
  try {
    servotwin::io::require_varying(t, "u");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, "rec.csv");
    EXPECT_EQ(e.where().field, "u");
    EXPECT_THAT(e.what(), HasSubstr("column 'u' is constant (2.5 in all 3 rows)"));
  }
  EXPECT_NO_THROW(servotwin::io::require_varying(t, "y"));
}

TEST(SignalCsv, ReadsTheFdiToolsRecording) {
  SignalReadOptions o;
  o.columns = {"iq_adx", "theta_mx"};
  const auto t = servotwin::io::read_signal_file(
      std::string(SERVOTWIN_REPO_DATA_DIR) + "/twomass-motor-bench-fditools/MultisineTypeA.csv", o);
  EXPECT_EQ(t.size(), 50000u);
  EXPECT_EQ(t.ts, 1.0 / 2500.0);
  EXPECT_EQ(t.column("iq_adx")[1], 10.58191);  // second data row of the file
  EXPECT_EQ(t.column("theta_mx")[0], -7.456285);
  EXPECT_THAT([] { servotwin::io::read_signal_file("/nonexistent/rec.csv"); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("cannot open")));
}

}  // namespace signal_csv_test
}  // namespace
