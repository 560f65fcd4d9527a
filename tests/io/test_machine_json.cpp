// Machine description JSON: round trip of every preset, and errors that name the field.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "servotwin/core/error.hpp"
#include "servotwin/io/machine_json.hpp"
#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/machine/presets.hpp"

namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace machine_json_test {

using servotwin::core::InputError;
using servotwin::io::parse_machine_json;
using ::testing::HasSubstr;

std::string error_of(const std::string& text) {
  try {
    parse_machine_json(text, "m.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string minimal(const std::string& controller, const std::string& extra_axis = "", const std::string& extra_root = "") {
  return R"({"format": "servotwin.machine/1", "ts": 0.001, )" + extra_root +
         R"("axes": [{"name": "x", "plant": {"inertia": 0.1, "damping": 0.25, "gain": 100}, "controller": )" +
         controller + extra_axis + "}]}";
}

TEST(MachineJson, EveryPresetRoundTripsWithTheSameClosedLoop) {
  for (const auto& name : servotwin::machine::preset_names()) {
    SCOPED_TRACE(name);
    const auto original = servotwin::machine::preset(name);
    const std::string text = servotwin::io::machine_to_json(original).dump(2);
    const auto back = parse_machine_json(text, name + ".json");
    EXPECT_EQ(servotwin::io::machine_to_json(back), servotwin::io::machine_to_json(original));
    for (std::size_t i = 0; i < original.axes.size(); ++i) {
      const auto a = servotwin::machine::equivalent_closed_loop(original.axes[i], original.ts).coefficients;
      const auto b = servotwin::machine::equivalent_closed_loop(back.axes[i], back.ts).coefficients;
      EXPECT_DOUBLE_EQ(a.a1, b.a1);
      EXPECT_DOUBLE_EQ(a.a3, b.a3);
      EXPECT_DOUBLE_EQ(a.b2, b.b2);
      EXPECT_DOUBLE_EQ(a.d1, b.d1);
    }
  }
}

TEST(MachineJson, ReadsAMinimalPidMachineWithDefaults) {
  const auto m = parse_machine_json(minimal(R"({"type": "pid", "kp": 44.35623, "ki": 316.83021, "kd": 0.1901})"), "m.json");
  EXPECT_EQ(m.name, "m");
  ASSERT_EQ(m.axes.size(), 1U);
  const auto& pid = std::get<servotwin::machine::PidController>(m.axes[0].controller);
  EXPECT_DOUBLE_EQ(pid.kp, 44.35623);
  EXPECT_DOUBLE_EQ(pid.vel_ff, 0.0);
  EXPECT_EQ(m.axes[0].nonlinear.dac_bits, 0);
  // Closed form (thesis Eq. 3.5): a2 = K kp / J = 100 * 44.35623 / 0.1.
  EXPECT_NEAR(servotwin::machine::equivalent_closed_loop(m.axes[0], m.ts).coefficients.a2, 44356.23, 1e-9);
}

TEST(MachineJson, ErrorsNameTheField) {
  EXPECT_THAT(error_of(minimal(R"({"type": "pid", "kp": 1, "ki": 0, "kd": 0, "kq": 3})")),
              HasSubstr("m.json (axes[0].controller.kq): unknown field"));
  EXPECT_THAT(error_of(minimal(R"({"type": "pid", "kp": "high", "ki": 0, "kd": 0})")),
              HasSubstr("(axes[0].controller.kp): expected a number, found string"));
  EXPECT_THAT(error_of(minimal(R"({"type": "pi", "kp": 1})")), HasSubstr("unknown controller type 'pi'"));
  EXPECT_THAT(error_of(minimal(R"({"type": "pid", "ki": 0, "kd": 0})")),
              HasSubstr("(axes[0].controller.kp): missing required field"));
  EXPECT_THAT(error_of(minimal(R"({"type": "pid", "kp": 1, "ki": 0, "kd": 0})", R"(, "backlash": {"feedback": "scale"})")),
              HasSubstr("axes[0].backlash.feedback"));
  EXPECT_THAT(error_of(minimal(R"({"type": "pid", "kp": 1, "ki": 0, "kd": 0})", "", R"("tss": 1, )")),
              HasSubstr("(tss): unknown field"));
}

TEST(MachineJson, ValidationErrorsKeepTheFileName) {
  const std::string text = R"({"format": "servotwin.machine/1", "ts": 0.001, "axes": [{"name": "x",
      "plant": {"inertia": -0.1, "gain": 100}, "controller": {"type": "pid", "kp": 1, "ki": 0, "kd": 0}}]})";
  const std::string e = error_of(text);
  EXPECT_THAT(e, HasSubstr("m.json"));
  EXPECT_THAT(e, HasSubstr("inertia"));
}

TEST(MachineJson, SyntaxErrorsHaveLineAndColumn) {
  const std::string e = error_of("{\n  \"format\": \"servotwin.machine/1\",\n  \"ts\": 0.001,,\n}");
  EXPECT_THAT(e, HasSubstr("m.json:3:"));
  EXPECT_THAT(e, HasSubstr("invalid JSON"));
}

// nlohmann's parser reports a number that overflows a double as out_of_range, not parse_error:
// it must still reach the user as an input error naming the file (found by a fuzzing review).
TEST(MachineJson, ANumberBeyondTheDoubleRangeIsAnInputError) {
  const std::string e = error_of(R"({"format": "servotwin.machine/1", "ts": 1e999})");
  EXPECT_THAT(e, HasSubstr("m.json"));
  EXPECT_THAT(e, HasSubstr("does not fit a double"));
}

TEST(MachineJson, FormatIsChecked) {
  EXPECT_THAT(error_of(R"({"ts": 0.001})"), HasSubstr("missing \"format\""));
  EXPECT_THAT(error_of(R"({"format": "servotwin.machine/2", "ts": 0.001})"), HasSubstr("unsupported version"));
  EXPECT_THAT(error_of(R"({"format": "servotwin.axis-model/1"})"), HasSubstr("expected \"servotwin.machine/1\""));
  EXPECT_THAT(error_of("[1, 2]"), HasSubstr("expected a JSON object"));
}

TEST(MachineJson, ClosedLoopReportHasThesisTable34Coefficients) {
  const auto report = servotwin::io::closed_loop_report(servotwin::machine::preset("fadal-pid"));
  ASSERT_EQ(report["axes"].size(), 2U);
  const auto& x = report["axes"][0];
  EXPECT_EQ(x["name"], "x");
  // Thesis Table 3.4, "Actual" column, X axis (printed to 2 decimals).
  EXPECT_NEAR(x["closed_loop"]["a1"].get<double>(), 192.65, 0.005);
  EXPECT_NEAR(x["closed_loop"]["a2"].get<double>(), 44356.23, 0.005);
  EXPECT_NEAR(x["closed_loop"]["a3"].get<double>(), 316830.21, 0.005);
  EXPECT_NEAR(x["closed_loop"]["b1"].get<double>(), 190.10, 0.005);
  EXPECT_NEAR(x["closed_loop"]["d0"].get<double>(), 441.0, 0.005);
  EXPECT_NEAR(x["closed_loop"]["d1"].get<double>(), -302.0, 0.005);
  EXPECT_EQ(x["poles"].size(), 3U);
}

}  // namespace machine_json_test
}  // namespace
