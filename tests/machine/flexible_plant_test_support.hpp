#pragma once
// Shared by the flexible-plant tests: the scipy fixture (tools/reference/flexible_plant_reference.py)
// and the error measure the comparisons use.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "json_fixture.hpp"

namespace servotwin::machine::test {

inline const nlohmann::json& fixture() {
  static const nlohmann::json data =
      test_support::read_json_fixture("machine/flexible_plant_reference.json", "flexible_plant_reference.py");
  return data;
}

inline std::vector<double> vec(const nlohmann::json& j) { return j.get<std::vector<double>>(); }

/// max |got - want| / max |want| (0/0 when want is all zero is the caller's problem).
inline double max_relative_error(const std::vector<double>& got, const std::vector<double>& want) {
  double scale = 0.0, diff = 0.0;
  for (std::size_t i = 0; i < want.size(); ++i) {
    scale = std::max(scale, std::abs(want[i]));
    diff = std::max(diff, std::abs(got[i] - want[i]));
  }
  return diff / scale;
}

}  // namespace servotwin::machine::test
