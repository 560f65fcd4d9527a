#pragma once
// Access to tests/data/rapid/axis_model_reference.json, written by
// tools/reference/axis_model_reference.py (numpy/scipy). Every expected value read through these
// helpers comes from that script.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "servotwin/rapid/axis_model.hpp"

namespace servotwin::rapid::test {

inline const nlohmann::json& axis_model_reference() {
  static const nlohmann::json data = [] {
    const std::string path = std::string(SERVOTWIN_TEST_DATA_DIR) + "/rapid/axis_model_reference.json";
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path + " (run tools/reference/axis_model_reference.py)");
    return nlohmann::json::parse(in);
  }();
  return data;
}

inline ModelCoefficients coefficients_from_json(const nlohmann::json& j) {
  ModelCoefficients c;
  c.a1 = j.at("a1").get<double>();
  c.a2 = j.at("a2").get<double>();
  c.a3 = j.at("a3").get<double>();
  c.b0 = j.at("b0").get<double>();
  c.b1 = j.at("b1").get<double>();
  c.b2 = j.at("b2").get<double>();
  c.d0 = j.at("d0").get<double>();
  c.d1 = j.at("d1").get<double>();
  return c;
}

inline ModelCoefficients reference_model(const std::string& name) {
  return coefficients_from_json(axis_model_reference().at("models").at(name).at("coefficients"));
}

/// A simulation case of section "linear" or "friction".
inline const nlohmann::json& simulation_case(const std::string& section, const std::string& name) {
  for (const auto& c : axis_model_reference().at(section))
    if (c.at("name") == name) return c;
  throw std::runtime_error("no case " + name + " in section " + section);
}

inline std::vector<double> doubles(const nlohmann::json& j) { return j.get<std::vector<double>>(); }

/// Trapezoidal-velocity command 0 -> distance -> 0 ... built from constant-acceleration phases,
/// sampled at ts (for tests that do not need a fixture).
inline std::vector<double> back_and_forth(double distance, double speed, double accel, double ts, double dwell,
                                          int cycles) {
  std::vector<double> out;
  double x = 0.0;
  const auto rest = [&](double seconds) {
    for (int k = 0; k < static_cast<int>(seconds / ts); ++k) out.push_back(x);
  };
  const auto move = [&](double target) {
    const double start = x, d = target - start, sign = d >= 0 ? 1.0 : -1.0, a = std::abs(d);
    double ta = speed / accel, vp = speed;
    double tc = (a - accel * ta * ta) / speed;
    if (tc < 0) {
      ta = std::sqrt(a / accel);
      vp = accel * ta;
      tc = 0;
    }
    const double total = 2 * ta + tc;
    for (double t = ts; t < total; t += ts) {
      double p;
      if (t < ta) p = 0.5 * accel * t * t;
      else if (t < ta + tc) p = 0.5 * accel * ta * ta + vp * (t - ta);
      else p = a - 0.5 * accel * (total - t) * (total - t);
      out.push_back(start + sign * p);
    }
    x = target;
    out.push_back(x);
  };
  rest(dwell);
  for (int c = 0; c < cycles; ++c) {
    move(distance);
    rest(dwell);
    move(0.0);
    rest(dwell);
  }
  return out;
}

/// Every coefficient of `actual` within `rel` of `expected`'s (relative to each coefficient).
inline void expect_coefficients_near(const ModelCoefficients& actual, const ModelCoefficients& expected, double rel) {
  EXPECT_NEAR(actual.a1, expected.a1, rel * std::abs(expected.a1));
  EXPECT_NEAR(actual.a2, expected.a2, rel * std::abs(expected.a2));
  EXPECT_NEAR(actual.a3, expected.a3, rel * std::abs(expected.a3));
  EXPECT_NEAR(actual.b0, expected.b0, rel * std::abs(expected.b0));
  EXPECT_NEAR(actual.b1, expected.b1, rel * std::abs(expected.b1));
  EXPECT_NEAR(actual.b2, expected.b2, rel * std::abs(expected.b2));
  EXPECT_NEAR(actual.d0, expected.d0, rel * std::abs(expected.d0));
  EXPECT_NEAR(actual.d1, expected.d1, rel * std::abs(expected.d1));
}

}  // namespace servotwin::rapid::test
