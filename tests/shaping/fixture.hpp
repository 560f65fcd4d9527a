#pragma once
// Test helper: reads the fixtures written by tools/reference/shaping_reference.py.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "servotwin/shaping/shaper.hpp"

namespace servotwin::shaping::test {

inline nlohmann::json load_fixture(const std::string& name) {
  std::ifstream in(std::string(SERVOTWIN_TEST_DATA_DIR) + "/shaping/" + name);
  if (!in) throw std::runtime_error("missing fixture tests/data/shaping/" + name);
  return nlohmann::json::parse(in);
}

inline Shaper shaper_from(const nlohmann::json& row, double omega = 1.0, double zeta = 0.0) {
  Shaper s;
  s.type = "fixture";
  s.omega = omega;
  s.zeta = zeta;
  s.times = row.at("times").get<std::vector<double>>();
  s.amplitudes = row.at("amplitudes").get<std::vector<double>>();
  return s;
}

/// Element-wise EXPECT_NEAR with the index in the message.
inline void expect_near_all(const std::vector<double>& actual, const std::vector<double>& expected, double tol) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) EXPECT_NEAR(actual[i], expected[i], tol) << "index " << i;
}

}  // namespace servotwin::shaping::test
