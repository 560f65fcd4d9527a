// Balanced truncation (core/model_reduction.hpp). Expected values: GNU Octave's control package
// (hsvd; btamodred, square-root method: SLICOT AB09ID) in tests/data/core/model_reduction_reference.json,
// written by tools/reference/model_reduction_reference.m; and the closed-form properties of a
// balanced truncation (Glover's error bounds, the reduced model's own Hankel singular values).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

#include "json_fixture.hpp"
#include "servotwin/core/model_reduction.hpp"
#include "servotwin/core/norms.hpp"

namespace servotwin::core {
namespace {
namespace model_reduction_test {

const nlohmann::json& fixture() {
  static const nlohmann::json data =
      test_support::read_json_fixture("core/model_reduction_reference.json", "model_reduction_reference.m");
  return data;
}

Eigen::MatrixXd matrix(const nlohmann::json& v, Eigen::Index rows, Eigen::Index cols) {
  return test_support::octave_matrix(v, rows, cols);
}

StateSpace system_of(const nlohmann::json& c) {
  const auto n = static_cast<Eigen::Index>(c["hsv"].size());
  const auto p = c["reduced"][0]["outputs"].get<Eigen::Index>();
  const auto m = c["reduced"][0]["inputs"].get<Eigen::Index>();
  return {matrix(c["A"], n, n), matrix(c["B"], n, m), matrix(c["C"], p, n), matrix(c["D"], p, m)};
}

/// G1 - G2 as one state-space system.
StateSpace difference(const StateSpace& g1, const StateSpace& g2) {
  const Eigen::Index n1 = g1.states(), n2 = g2.states();
  StateSpace d;
  d.A = Eigen::MatrixXd::Zero(n1 + n2, n1 + n2);
  d.A.topLeftCorner(n1, n1) = g1.A;
  d.A.bottomRightCorner(n2, n2) = g2.A;
  d.B.resize(n1 + n2, g1.inputs());
  d.B << g1.B, g2.B;
  d.C.resize(g1.outputs(), n1 + n2);
  d.C << g1.C, -g2.C;
  d.D = g1.D - g2.D;
  return d;
}

TEST(BalancedTruncation, MatchesOctaveHankelValuesAndReducedResponses) {
  for (const auto& c : fixture()["cases"]) {
    const std::string name = c["name"];
    const StateSpace g = system_of(c);
    const Eigen::VectorXd hsv = hankel_singular_values(g);
    ASSERT_EQ(hsv.size(), static_cast<Eigen::Index>(c["hsv"].size())) << name;
    for (Eigen::Index i = 0; i < hsv.size(); ++i)
      EXPECT_NEAR(hsv[i], c["hsv"][static_cast<std::size_t>(i)].get<double>(), 1e-9 * hsv[0]) << name << " hsv " << i;
    for (const auto& r : c["reduced"]) {
      const auto order = r["order"].get<Eigen::Index>();
      const BalancedTruncation bt = balanced_truncation(g, order);
      ASSERT_EQ(bt.reduced.states(), order) << name;
      const auto p = g.outputs(), m = g.inputs();
      std::size_t k = 0;  // column-major over (output, input, frequency)
      for (const auto& w : c["omega"]) {
        const Eigen::MatrixXcd h = frequency_response(bt.reduced, w.get<double>());
        for (Eigen::Index j = 0; j < m; ++j) {
          for (Eigen::Index i = 0; i < p; ++i, ++k) {
            const std::complex<double> expected(r["re"][k].get<double>(), r["im"][k].get<double>());
            // Near-equal discarded/kept values (two_mass at order 1: 6.5040 / 6.5033) make the
            // truncation itself sensitive: compared to 1e-6 of the response's scale.
            EXPECT_NEAR(std::abs(h(i, j) - expected), 0.0, 1e-6 * std::max(1.0, std::abs(expected)))
                << name << " order " << order << " w " << w << " (" << i << "," << j << ")";
          }
        }
      }
    }
  }
}

TEST(BalancedTruncation, ErrorLiesBetweenGloversBounds) {
  // sigma_{r+1} <= ||G - G_r||_inf <= 2 sum_{i>r} sigma_i (distinct values), and the reduced model
  // is balanced: its Hankel singular values are the retained ones.
  for (const auto& c : fixture()["cases"]) {
    const StateSpace g = system_of(c);
    for (Eigen::Index order = 1; order < g.states(); ++order) {
      const BalancedTruncation bt = balanced_truncation(g, order);
      const double error = hinf_norm(difference(g, bt.reduced)).value;
      EXPECT_LE(error, bt.error_bound * (1.0 + 1e-6)) << c["name"] << " order " << order;
      EXPECT_GE(error, bt.hankel[order] * (1.0 - 1e-6)) << c["name"] << " order " << order;
      const Eigen::VectorXd kept = hankel_singular_values(bt.reduced);
      for (Eigen::Index i = 0; i < order; ++i) EXPECT_NEAR(kept[i], bt.hankel[i], 1e-8 * bt.hankel[0]) << c["name"];
    }
  }
}

TEST(BalancedTruncation, FullOrderKeepsTheResponseAndZeroOrderKeepsD) {
  const StateSpace g = system_of(fixture()["cases"][2]);
  const BalancedTruncation full = balanced_truncation(g, g.states());
  EXPECT_EQ(full.error_bound, 0.0);
  for (const double w : {0.0, 0.3, 3.0, 30.0})
    EXPECT_LT((frequency_response(full.reduced, w) - frequency_response(g, w)).norm(), 1e-10) << w;
  const BalancedTruncation none = balanced_truncation(g, 0);
  EXPECT_EQ(none.reduced.states(), 0);
  EXPECT_EQ(none.reduced.D, g.D);
}

TEST(BalancedTruncation, ScalesWithTheSystem) {
  // k G has Hankel singular values k sigma_i and the same reduced model times k.
  const StateSpace g = system_of(fixture()["cases"][0]);
  StateSpace k = g;
  k.C *= 1000.0;
  const Eigen::VectorXd a = hankel_singular_values(g), b = hankel_singular_values(k);
  for (Eigen::Index i = 0; i < a.size(); ++i) EXPECT_NEAR(b[i], 1000.0 * a[i], 1e-9 * 1000.0 * a[0]);
  const auto ra = balanced_truncation(g, 2).reduced, rb = balanced_truncation(k, 2).reduced;
  for (const double w : {0.5, 5.0})
    EXPECT_NEAR(std::abs(frequency_response(rb, w)(0, 0) - 1000.0 * frequency_response(ra, w)(0, 0)), 0.0,
                1e-8 * 1000.0 * std::abs(frequency_response(ra, w)(0, 0)));
}

TEST(BalancedTruncation, RefusesUnstableSystemsAndBadOrders) {
  StateSpace rigid{Eigen::MatrixXd::Zero(1, 1), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Ones(1, 1),
                   Eigen::MatrixXd::Zero(1, 1)};  // an integrator: a two-mass plant's rigid-body mode
  EXPECT_THROW((void)hankel_singular_values(rigid), std::domain_error);
  const StateSpace g = system_of(fixture()["cases"][1]);
  EXPECT_THROW((void)balanced_truncation(g, 4), std::invalid_argument);
  EXPECT_THROW((void)balanced_truncation(g, -1), std::invalid_argument);
  StateSpace bad = g;
  bad.B.resize(2, 1);
  EXPECT_THROW((void)hankel_singular_values(bad), std::invalid_argument);
}

}  // namespace model_reduction_test
}  // namespace
}  // namespace servotwin::core
