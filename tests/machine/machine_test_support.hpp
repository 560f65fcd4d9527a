#pragma once
// Shared helpers of the machine tests.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "servotwin/core/state_space.hpp"
#include "servotwin/machine/closed_loop.hpp"

namespace servotwin::machine::test {

/// tests/data/machine/machine_reference.json, written by tools/reference/machine_reference.py.
inline const nlohmann::json& reference() {
  static const nlohmann::json data = [] {
    std::ifstream in(std::string(SERVOTWIN_TEST_DATA_DIR) + "/machine/machine_reference.json");
    return nlohmann::json::parse(in);
  }();
  return data;
}

inline std::vector<double> to_vector(const nlohmann::json& j) { return j.get<std::vector<double>>(); }

/// max |a - b| / max(max |b|, floor).
inline double relative_max_difference(std::span<const double> a, std::span<const double> b, double floor = 1e-300) {
  double diff = 0.0, scale = floor;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    diff = std::max(diff, std::abs(a[i] - b[i]));
    scale = std::max(scale, std::abs(b[i]));
  }
  return diff / scale;
}

/// Output `output` of the exact sampled loop for a command (input 0 at sample k is
/// x_r(k + preview); the command is held at its last value beyond the end) and disturbance d.
inline std::vector<double> simulate_loop(const DiscreteClosedLoop& loop, std::span<const double> command,
                                         std::span<const double> disturbance = {}, int output = 0) {
  const auto n = static_cast<Eigen::Index>(command.size());
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto ahead = std::min<std::size_t>(static_cast<std::size_t>(k + loop.preview), command.size() - 1);
    u(k, 0) = command[ahead];
    if (!disturbance.empty()) u(k, 1) = disturbance[static_cast<std::size_t>(k)];
  }
  const Eigen::MatrixXd y = core::simulate(loop.system, u);
  std::vector<double> out(static_cast<std::size_t>(n));
  for (Eigen::Index k = 0; k < n; ++k) out[static_cast<std::size_t>(k)] = y(k, output);
  return out;
}

}  // namespace servotwin::machine::test
