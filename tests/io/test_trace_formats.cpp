// Controller trace formats: LinuxCNC halsampler output and halscope logs, the HAL and INI files
// that name a halsampler trace's columns and give its period, and trace profiles. Expected values
// come from the layouts in LinuxCNC 2.9's sources (sampler_usr.c: values "%f " per pin, the sample
// number first with -t, "overrun" lines; scope_files.c: "# Sampling period is %i ns", ';'-joined
// names and "%.14f" values), from the sample files' own text (a real trace of the integration rig,
// data/profiles/samples/), and from synthetic input built here.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "servotwin/core/error.hpp"
#include "servotwin/io/capture_csv.hpp"
#include "servotwin/io/linuxcnc_config.hpp"
#include "servotwin/io/trace_profile.hpp"

namespace trace_formats_test {
namespace {

using servotwin::core::Capture;
using servotwin::core::InputError;
using servotwin::io::CaptureReadOptions;
using servotwin::io::TraceFormat;
using ::testing::HasSubstr;

const std::string kProfiles = std::string(SERVOTWIN_REPO_DATA_DIR) + "/profiles/";
const std::string kRig = std::string(SERVOTWIN_REPO_DATA_DIR) + "/../integration/linuxcnc/";

CaptureReadOptions halsampler(std::vector<std::string> columns, double ts = 0.001) {
  CaptureReadOptions o;
  o.format = TraceFormat::Halsampler;
  o.columns = std::move(columns);
  o.ts = ts;
  return o;
}

Capture read_text(const std::string& text, const CaptureReadOptions& o) {
  std::istringstream in(text);
  return servotwin::io::read_capture_csv(in, "trace.txt", o);
}

std::string error_text(const std::string& text, const CaptureReadOptions& o) {
  try {
    (void)read_text(text, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

/// A temporary file holding `text`, removed at the end of the test.
class TempFile {
 public:
  TempFile(const std::string& name, const std::string& text)
      : path_(std::filesystem::temp_directory_path() / ("servotwin-trace-" + std::to_string(::getpid()) + "-" + name)) {
    std::ofstream(path_) << text;
  }
  ~TempFile() { std::filesystem::remove(path_); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

TEST(Halsampler, ReadsWithAndWithoutSampleNumbers) {
  // Two pins (cfg=ff) as halsampler -t prints them: number, values each with a trailing blank.
  const CaptureReadOptions o = halsampler({"x_cmd", "x_act"});
  const Capture numbered = read_text("17 0.100000 0.050000 \n18 0.200000 0.150000 \n19 0.300000 0.250000 \n", o);
  const Capture plain = read_text("0.100000 0.050000 \n0.200000 0.150000 \n0.300000 0.250000 \n", o);
  for (const Capture* c : {&numbered, &plain}) {
    ASSERT_EQ(c->size(), 3u);
    EXPECT_EQ(c->ts, 0.001);
    EXPECT_EQ(c->axes[0].cmd[2], 0.3);
    EXPECT_EQ(c->axes[0].act[1], 0.15);
  }
  // The 32-bit counter LinuxCNC 2.9 prints signed: 2^31 - 1 is followed by -2^31.
  EXPECT_EQ(read_text("2147483647 1 2 \n-2147483648 3 4 \n", o).size(), 2u);
  // A halsampler started late reports 'overrun' before its first line: the data are whole.
  EXPECT_EQ(read_text("overrun\n5 1 2 \n6 3 4 \n", o).size(), 2u);
  // Killed halsampler: the last line cut short (no line end) is left out.
  EXPECT_EQ(read_text("5 1 2 \n6 3 4 \n7 5", o).size(), 2u);
  // Columns named something else are read only when mapped.
  CaptureReadOptions mapped = halsampler({"st-x-cmd", "st-x-fb", "spare"});
  mapped.map = {{"x_cmd", "st-x-cmd"}, {"x_act", "st-x-fb"}};
  EXPECT_EQ(read_text("1 2 9 \n3 4 9 \n", mapped).axes[0].act[1], 4.0);
}

TEST(Halsampler, GapsAndMissingColumnsAreErrorsAtTheirLine) {
  const CaptureReadOptions o = halsampler({"x_cmd", "x_act", "x_u"});
  EXPECT_THAT(error_text("5 1 2 3 \n6 1 2 3 \n9 1 2 3 \n", o), HasSubstr("trace.txt:3:1 (sample): sample number jumps from 6 to 9: 2 samples lost"));
  EXPECT_THAT(error_text("5 1 2 3 \n6 1 2 3 \noverrun\n7 1 2 3 \n", o), HasSubstr("trace.txt:3: 'overrun'"));
  EXPECT_THAT(error_text("1 2 \n1 2 \n", o), HasSubstr("trace.txt:1: 2 values on the line but 3 columns named"));
  EXPECT_THAT(error_text("1 1 2 3 \n2 1 2 \n3 1 2 3 \n", o), HasSubstr("trace.txt:2: 3 values on the line, expected 4"));
  EXPECT_THAT(error_text("x 1 2 3 \n", o), HasSubstr("sample number"));
  // One name too many: the sample number would be read as x_cmd and every column shifted.
  EXPECT_THAT(error_text("7 1 2 \n8 1 2 \n9 1 2 \n", o), HasSubstr("trace.txt:3:1 (x_cmd): the first column counts 1 by 1"));
  EXPECT_THAT(error_text("1 2 3 \n", halsampler({})), HasSubstr("--columns"));
  CaptureReadOptions no_period = o;
  no_period.ts.reset();
  EXPECT_THAT(error_text("1 2 3 \n4 5 6 \n", no_period), HasSubstr("--ts or --ini"));
}

TEST(Halscope, ReadsThePeriodAndTheJointPinsOfALog) {
  CaptureReadOptions o;
  o.format = TraceFormat::Halscope;
  const std::string log =
      "# Sampling period is 250000 ns\n"
      "joint.0.motor-pos-cmd;joint.0.motor-pos-fb;pid.x.output\n"
      "1.00000000000000;0.50000000000000;3.00000000000000\n"
      "2.00000000000000;1.50000000000000;4.00000000000000\n";
  const Capture c = read_text(log, o);
  EXPECT_DOUBLE_EQ(c.ts, 250e-6);
  ASSERT_EQ(c.axes.size(), 1u);
  EXPECT_EQ(c.axes[0].name, "x");
  EXPECT_EQ(c.axes[0].act[1], 1.5);
  EXPECT_TRUE(c.axes[0].u.empty());
  // Newer halscope versions add '# Position:' and '# Scale:' lines after the names: comments.
  CaptureReadOptions with_u = o;
  with_u.map = {{"x_u", "pid.x.output"}};
  const std::string newer = log.substr(0, log.find("1.0000")) + "# Position: 0;0;0;\n# Scale: 1;1;1;\n" +
                            log.substr(log.find("1.0000"));
  EXPECT_EQ(read_text(newer, with_u).axes[0].u[1], 4.0);
  // Joint 1 drives Z on an XZ lathe: the INI's coordinates say so.
  CaptureReadOptions lathe = o;
  lathe.joint_axes = "XZ";
  const Capture z = read_text("# Sampling period is 1000000 ns\njoint.1.motor-pos-cmd;joint.1.motor-pos-fb\n1;1\n2;2\n", lathe);
  EXPECT_EQ(z.axes[0].name, "z");
  EXPECT_THAT(error_text("joint.0.motor-pos-cmd;joint.0.motor-pos-fb\n1;1\n2;2\n", o), HasSubstr("Sampling period"));
  EXPECT_THAT(error_text("# Sampling period is 0 ns\na;b\n", o), HasSubstr("n > 0"));
  CaptureReadOptions other_ts = o;
  other_ts.ts = 0.001;
  EXPECT_THAT(error_text(log, other_ts), HasSubstr("disagrees"));
}

TEST(LinuxCncConfig, TheRigsHalAndIniNameTheColumnsAndThePeriod) {
  const servotwin::io::LinuxCncIni ini = servotwin::io::read_linuxcnc_ini(kRig + "servotwin_sim.ini");
  ASSERT_TRUE(ini.servo_period_s.has_value());
  EXPECT_DOUBLE_EQ(*ini.servo_period_s, 0.001);  // SERVO_PERIOD = 1000000 ns
  EXPECT_EQ(ini.joint_axes, "XYZ");
  const auto hal = servotwin::io::read_hal_sampler_columns(kRig + "servotwin_sim.hal", 0, &ini);
  EXPECT_EQ(hal.columns, (std::vector<std::string>{"x_cmd", "x_act", "x_u", "y_cmd", "y_act", "y_u", "z_cmd", "z_act", "z_u"}));
  EXPECT_EQ(hal.signals[2], "st-x-force");
  EXPECT_EQ(hal.thread, "servo-thread");
  ASSERT_TRUE(hal.period_s.has_value());
  EXPECT_DOUBLE_EQ(*hal.period_s, 0.001);
}

TEST(LinuxCncConfig, HalcmdSubsetAndItsErrors) {
  const TempFile ini("lathe.ini", "[EMCMOT]\nSERVO_PERIOD = 500000\nBASE_PERIOD=25000\n[KINS]\nKINEMATICS = trivkins coordinates=XZ\n");
  const TempFile hal("lathe.hal",
                     "loadrt sampler depth=4096 cfg=ffb,ff  # two samplers\n"
                     "addf sampler.1 base-thread\n"
                     "net zc joint.1.motor-pos-cmd => pid.z.command \\\n"
                     "    sampler.1.pin.0\n"
                     "net spindle-speed spindle.0.speed-out => sampler.1.pin.1\n"
                     "linkps sampler.0.pin.0 xc\n"
                     "net xc joint.0.pos-cmd\n");
  const auto i = servotwin::io::read_linuxcnc_ini(ini.path());
  EXPECT_EQ(i.joint_axes, "XZ");
  const auto s1 = servotwin::io::read_hal_sampler_columns(hal.path(), 1, &i);
  EXPECT_EQ(s1.columns, (std::vector<std::string>{"z_cmd", "spindle-speed"}));
  ASSERT_TRUE(s1.period_s.has_value());
  EXPECT_DOUBLE_EQ(*s1.period_s, 25e-6);  // base-thread
  const auto s0 = servotwin::io::read_hal_sampler_columns(hal.path(), 0, &i);
  EXPECT_EQ(s0.columns, (std::vector<std::string>{"x_cmd", "sampler.0.pin.1", "sampler.0.pin.2"}));
  EXPECT_THAT([&] { (void)servotwin::io::read_hal_sampler_columns(hal.path(), 2, &i); },
              testing::ThrowsMessage<InputError>(HasSubstr("not sampler.2")));
  const TempFile none("none.hal", "loadrt pid names=pid.x\n");
  EXPECT_THAT([&] { (void)servotwin::io::read_hal_sampler_columns(none.path()); },
              testing::ThrowsMessage<InputError>(HasSubstr("loads no sampler")));
  const TempFile bad("bad.hal", "loadrt sampler cfg=fq\n");
  EXPECT_THAT([&] { (void)servotwin::io::read_hal_sampler_columns(bad.path()); },
              testing::ThrowsMessage<InputError>(HasSubstr("unknown type letter 'q'")));
  const TempFile bad_ini("bad.ini", "[EMCMOT]\nSERVO_PERIOD = fast\n");
  EXPECT_THAT([&] { (void)servotwin::io::read_linuxcnc_ini(bad_ini.path()); },
              testing::ThrowsMessage<InputError>(HasSubstr("bad.ini:2 ([EMCMOT]SERVO_PERIOD)")));
}

TEST(TraceProfile, ShippedProfilesReadTheirSamplesAlike) {
  // The same 300 servo cycles, once as halsampler wrote them and once in halscope's layout.
  const auto rig = servotwin::io::read_trace_profile(kProfiles + "linuxcnc-servotwin-rig.json");
  const auto scope = servotwin::io::read_trace_profile(kProfiles + "linuxcnc-halscope.json");
  const Capture a = servotwin::io::read_capture_file(kProfiles + "samples/linuxcnc-servotwin-rig.txt", rig.reading);
  const Capture b = servotwin::io::read_capture_file(kProfiles + "samples/linuxcnc-halscope.csv", scope.reading);
  ASSERT_EQ(a.size(), 300u);
  ASSERT_EQ(b.size(), 300u);
  EXPECT_EQ(a.ts, b.ts);
  // The sample file's first line: "179 0.324333 0.156824 126.013391 0.000000 ..."
  EXPECT_EQ(a.find("x")->cmd.front(), 0.324333);
  EXPECT_EQ(a.find("x")->u.front(), 126.013391);
  for (const char* axis : {"x", "y"}) {
    EXPECT_EQ(a.find(axis)->cmd, b.find(axis)->cmd) << axis;
    EXPECT_EQ(a.find(axis)->act, b.find(axis)->act) << axis;
    EXPECT_EQ(a.find(axis)->u, b.find(axis)->u) << axis;
  }
}

TEST(TraceProfile, RoundTripUnitsAndErrors) {
  servotwin::io::TraceProfile p;
  p.description = "scope export in metres";
  p.reading.delimiter = ';';
  p.reading.map = {{"t", "time"}, {"x_cmd", "X nominal"}};
  p.reading.scale = 1000.0;
  p.reading.ts = 0.0005;
  std::ostringstream out;
  servotwin::io::write_trace_profile(out, p);
  EXPECT_THAT(out.str(), HasSubstr("\"units\": \"m\""));
  const auto back = servotwin::io::parse_trace_profile(out.str(), "p.json");
  EXPECT_EQ(back.reading.scale, 1000.0);
  EXPECT_EQ(back.reading.delimiter, ';');
  EXPECT_EQ(back.reading.map, p.reading.map);
  EXPECT_EQ(back.reading.ts, 0.0005);
  EXPECT_EQ(back.description, p.description);
  const auto error = [](const std::string& text) {
    try {
      (void)servotwin::io::parse_trace_profile(text, "p.json");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head = R"({"format": "servotwin.trace-profile/1", )";
  EXPECT_THAT(error(head + R"("units": "m", "scale": 1})"), HasSubstr("disagrees with units 'm'"));
  EXPECT_THAT(error(head + R"("units": "furlong"})"), HasSubstr("units"));
  EXPECT_THAT(error(head + R"("trace_format": "tncscope"})"), HasSubstr("trace_format"));
  EXPECT_THAT(error(head + R"("colums": []})"), HasSubstr("colums"));
  EXPECT_THAT(error(R"({"format": "servotwin.trace-profile/2"})"), HasSubstr("servotwin.trace-profile/2"));
}

}  // namespace
}  // namespace trace_formats_test
