#pragma once
// Access to tests/data/frf/frf_observer_reference.json, written by
// tools/reference/frf_observer_reference.py (scipy). Every expected value read through these
// helpers comes from that script.

#include <Eigen/Dense>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace servotwin::frf::test {

inline const nlohmann::json& observer_reference() {
  static const nlohmann::json data = [] {
    const std::string path = std::string(SERVOTWIN_TEST_DATA_DIR) + "/frf/frf_observer_reference.json";
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path + " (run tools/reference/frf_observer_reference.py)");
    return nlohmann::json::parse(in);
  }();
  return data;
}

inline Eigen::MatrixXd json_matrix(const nlohmann::json& rows) {
  const auto r = static_cast<Eigen::Index>(rows.size());
  const auto c = r == 0 ? Eigen::Index{0} : static_cast<Eigen::Index>(rows.front().size());
  Eigen::MatrixXd m(r, c);
  for (Eigen::Index i = 0; i < r; ++i)
    for (Eigen::Index j = 0; j < c; ++j)
      m(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)].get<double>();
  return m;
}

inline Eigen::VectorXd json_vector(const nlohmann::json& values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i) v(static_cast<Eigen::Index>(i)) = values[i].get<double>();
  return v;
}

inline std::vector<double> json_doubles(const nlohmann::json& values) { return values.get<std::vector<double>>(); }

}  // namespace servotwin::frf::test
