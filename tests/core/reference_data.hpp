#pragma once
// Access to tests/data/core/core_reference.json, written by tools/reference/core_reference.py
// (scipy/numpy). Every expected value read through these helpers comes from that script.

#include <Eigen/Dense>
#include <algorithm>
#include <complex>
#include <fstream>
#include <limits>
#include <ostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "json_fixture.hpp"
#include "servotwin/core/transfer_function.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/core/state_space.hpp"

namespace servotwin::core {
/// Readable GoogleTest failure messages: coefficients highest power first.
inline void PrintTo(const Polynomial& p, std::ostream* os) {
  *os << "Polynomial{";
  for (std::size_t i = 0; i < p.coefficients().size(); ++i) *os << (i ? ", " : "") << p.coefficients()[i];
  *os << "}";
}
}  // namespace servotwin::core

namespace servotwin::core::test {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// A transfer function from coefficient lists (descending powers of s).
inline TransferFunction tf(std::vector<double> num, std::vector<double> den) {
  return {Polynomial(std::move(num)), Polynomial(std::move(den))};
}

inline const nlohmann::json& core_reference() {
  static const nlohmann::json data = test_support::read_json_fixture("core/core_reference.json", "core_reference.py");
  return data;
}

/// tests/data/core/control_reference.json, written by tools/reference/core_control_reference.py
/// (state-space algebra, Tustin, H-infinity norms).
inline const nlohmann::json& control_reference() {
  static const nlohmann::json data =
      test_support::read_json_fixture("core/control_reference.json", "core_control_reference.py");
  return data;
}

/// The cases of one section ("polynomial_roots", "tf2ss", ...).
inline const nlohmann::json& reference_section(const std::string& section) {
  return core_reference().at(section);
}

inline const nlohmann::json& reference_case(const std::string& section, const std::string& name) {
  for (const auto& c : reference_section(section))
    if (c.at("name") == name) return c;
  throw std::runtime_error("no case " + name + " in section " + section);
}

inline Eigen::MatrixXd to_matrix(const nlohmann::json& rows) {
  const auto r = static_cast<Eigen::Index>(rows.size());
  const auto c = r == 0 ? Eigen::Index{0} : static_cast<Eigen::Index>(rows.front().size());
  Eigen::MatrixXd m(r, c);
  for (Eigen::Index i = 0; i < r; ++i)
    for (Eigen::Index j = 0; j < c; ++j) m(i, j) = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)].get<double>();
  return m;
}

/// A StateSpace from a fixture object with members A, B, C, D.
inline StateSpace system_from(const nlohmann::json& s) {
  return StateSpace{to_matrix(s.at("A")), to_matrix(s.at("B")), to_matrix(s.at("C")), to_matrix(s.at("D"))};
}

/// The system called `name` in control_reference()["systems"].
inline StateSpace reference_system(const std::string& name) {
  for (const auto& s : control_reference().at("systems"))
    if (s.at("name") == name) return system_from(s);
  throw std::runtime_error("no system " + name + " in control_reference.json");
}

inline Eigen::VectorXd to_vector(const nlohmann::json& values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i) v(i) = values[static_cast<std::size_t>(i)].get<double>();
  return v;
}

/// [[re, im], ...] -> complex values.
inline std::vector<std::complex<double>> to_complex(const nlohmann::json& pairs) {
  std::vector<std::complex<double>> out;
  for (const auto& p : pairs) out.emplace_back(p.at(0).get<double>(), p.at(1).get<double>());
  return out;
}

/// Largest relative difference ||a - b||_max / max(||b||_max, floor).
inline double max_relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-300) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return std::numeric_limits<double>::infinity();
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), floor);
}

}  // namespace servotwin::core::test
