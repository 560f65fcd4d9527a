#include <gtest/gtest.h>

#include <string>

#include "servotwin/core/capture.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::core {
namespace {

TEST(SourceLocation, FormatsOnlyTheKnownParts) {
  EXPECT_EQ(to_string(SourceLocation{"cap.csv", 12, 3, "x_act"}), "cap.csv:12:3 (x_act)");
  EXPECT_EQ(to_string(SourceLocation{"cap.csv", 12, 0, ""}), "cap.csv:12");
  EXPECT_EQ(to_string(SourceLocation{"cap.csv", 0, 5, ""}), "cap.csv");  // a column without a line means nothing
  EXPECT_EQ(to_string(SourceLocation{"", 7, 0, ""}), "line 7");
  EXPECT_EQ(to_string(SourceLocation{"", 0, 0, "axes[0].plant.inertia"}), "(axes[0].plant.inertia)");
  EXPECT_EQ(to_string(SourceLocation{}), "");
}

TEST(InputError, PrefixesTheLocationAndKeepsTheParts) {
  const InputError e(SourceLocation{"model.json", 4, 9, "a1"}, "expected a number");
  EXPECT_EQ(std::string(e.what()), "model.json:4:9 (a1): expected a number");
  EXPECT_EQ(e.reason(), "expected a number");
  EXPECT_EQ(e.where().file, "model.json");
  EXPECT_EQ(e.where().line, 4U);
  const InputError plain("--ts must be > 0");
  EXPECT_EQ(std::string(plain.what()), "--ts must be > 0");
  EXPECT_EQ(plain.reason(), "--ts must be > 0");
  EXPECT_TRUE(plain.where().file.empty());
  // Callers catch it as a std::runtime_error too.
  EXPECT_THROW(throw InputError("x"), std::runtime_error);
}

TEST(Capture, SizeTimeAndCaseInsensitiveLookup) {
  Capture c;
  EXPECT_EQ(c.size(), 0U);
  c.t0 = 0.5;
  c.ts = 0.001;
  c.axes.push_back({"x", {0.0, 1.0, 2.0}, {0.0, 0.9, 1.9}, {}});
  c.axes.push_back({"y", {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {}});
  EXPECT_EQ(c.size(), 3U);
  EXPECT_DOUBLE_EQ(c.time(2), 0.502);
  ASSERT_NE(c.find("X"), nullptr);
  EXPECT_EQ(c.find("X")->name, "x");
  EXPECT_EQ(c.find("z"), nullptr);
  EXPECT_EQ(c.find("xy"), nullptr);
  const Capture& constant = c;
  ASSERT_NE(constant.find("y"), nullptr);
  c.find("y")->act[1] = 5.0;  // the mutable overload refers to the same trace
  EXPECT_EQ(constant.find("Y")->act[1], 5.0);
}

}  // namespace
}  // namespace servotwin::core
