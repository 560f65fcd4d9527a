#pragma once
// Reading the scipy-generated JSON fixtures under tests/data/ (shared by every test module).
#include <Eigen/Dense>
#include <cstddef>
#include <fstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace servotwin::test_support {

/// tests/data/<relative> parsed; std::runtime_error naming the generating script when missing.
inline nlohmann::json read_json_fixture(const std::string& relative, const std::string& script) {
  const std::string path = std::string(SERVOTWIN_TEST_DATA_DIR) + "/" + relative;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path + " (run tools/reference/" + script + ")");
  return nlohmann::json::parse(in);
}

/// A rows x cols matrix from GNU Octave's jsonencode, which writes a 1x1 matrix as a number and a
/// row or column vector as a flat list.
inline Eigen::MatrixXd octave_matrix(const nlohmann::json& v, Eigen::Index rows, Eigen::Index cols) {
  Eigen::MatrixXd m(rows, cols);
  if (v.is_number()) {
    m(0, 0) = v.get<double>();
    return m;
  }
  if (!v.front().is_array()) {
    for (Eigen::Index i = 0; i < rows * cols; ++i) m(rows == 1 ? 0 : i, rows == 1 ? i : 0) = v[static_cast<std::size_t>(i)];
    return m;
  }
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index j = 0; j < cols; ++j) m(i, j) = v[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  return m;
}

}  // namespace servotwin::test_support
