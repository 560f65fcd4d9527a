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
  const auto n = c["states"].get<Eigen::Index>();
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

bool has_unstable_part(const nlohmann::json& c) { return c["unstable"].get<int>() > 0; }

/// Compares the reduced model's frequency response with Octave's (column-major over output,
/// input, frequency) to 1e-6 of the response's scale.
void expect_octave_response(const StateSpace& reduced, const nlohmann::json& c, const nlohmann::json& r) {
  const std::string name = c["name"];
  const auto order = r["order"].get<Eigen::Index>();
  std::size_t k = 0;
  for (const auto& w : c["omega"]) {
    const Eigen::MatrixXcd h = frequency_response(reduced, w.get<double>());
    for (Eigen::Index j = 0; j < reduced.inputs(); ++j) {
      for (Eigen::Index i = 0; i < reduced.outputs(); ++i, ++k) {
        const std::complex<double> expected(r["re"][k].get<double>(), r["im"][k].get<double>());
        // Near-equal discarded/kept values (two_mass at order 1: 6.5040 / 6.5033) make the
        // truncation itself sensitive: compared to 1e-6 of the response's scale.
        EXPECT_NEAR(std::abs(h(i, j) - expected), 0.0, 1e-6 * std::max(1.0, std::abs(expected)))
            << name << " order " << order << " w " << w << " (" << i << "," << j << ")";
      }
    }
  }
}

TEST(BalancedTruncation, MatchesOctaveHankelValuesAndReducedResponses) {
  for (const auto& c : fixture()["cases"]) {
    if (has_unstable_part(c)) continue;
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
      expect_octave_response(bt.reduced, c, r);
    }
  }
}

TEST(BalancedTruncation, ErrorLiesBetweenGloversBounds) {
  // sigma_{r+1} <= ||G - G_r||_inf <= 2 sum_{i>r} sigma_i (distinct values), and the reduced model
  // is balanced: its Hankel singular values are the retained ones.
  for (const auto& c : fixture()["cases"]) {
    if (has_unstable_part(c)) continue;
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

/// The eigenvalues of A (none for a zero-state system, where Eigen's solver must not be called).
Eigen::VectorXcd poles(const StateSpace& g) {
  return g.states() == 0 ? Eigen::VectorXcd() : Eigen::VectorXcd(g.A.eigenvalues());
}

TEST(StableSplit, SumsToTheSystemWithThePolesSeparated) {
  // Gs + Gu = G at every frequency; Gs has the poles left of the boundary, Gu the others (the
  // C7.19 controller: its integrator and unstable pair 0.48 +- 1.63j, stable pair of 22.35 s + 274.2).
  for (const auto& c : fixture()["cases"]) {
    const StateSpace g = system_of(c);
    const StableSplit split = stable_split(g, kStableBoundary);
    EXPECT_EQ(split.unstable.states(), c["unstable"].get<Eigen::Index>()) << c["name"];
    EXPECT_EQ(split.stable.states() + split.unstable.states(), g.states());
    for (const std::complex<double>& p : poles(split.stable)) EXPECT_LT(p.real(), kStableBoundary);
    for (const std::complex<double>& p : poles(split.unstable)) EXPECT_GE(p.real(), kStableBoundary);
    for (const double w : {0.05, 0.7, 1.63, 9.0, 120.0}) {
      const Eigen::MatrixXcd sum = frequency_response(split.stable, w) + frequency_response(split.unstable, w);
      const Eigen::MatrixXcd h = frequency_response(g, w);
      EXPECT_LT((sum - h).norm(), 1e-9 * std::max(1.0, h.norm())) << c["name"] << " w " << w;
    }
  }
}

TEST(BalancedTruncation, StablePartMatchesOctavesBtamodredOnUnstableControllers) {
  // btamodred (SLICOT AB09MD) keeps the poles right of -sqrt(eps) and reduces the rest; hsvd's
  // finite values are those of the stable part.
  int checked = 0;
  for (const auto& c : fixture()["cases"]) {
    if (!has_unstable_part(c)) continue;
    const StateSpace g = system_of(c);
    for (const auto& r : c["reduced"]) {
      const auto order = r["order"].get<Eigen::Index>();
      const BalancedTruncation bt = balanced_truncation_stable_part(g, order);
      ASSERT_EQ(bt.reduced.states(), order) << c["name"];
      EXPECT_EQ(bt.unstable_states, c["unstable"].get<Eigen::Index>());
      ASSERT_EQ(bt.hankel.size(), static_cast<Eigen::Index>(c["hsv"].size()));
      for (Eigen::Index i = 0; i < bt.hankel.size(); ++i)
        EXPECT_NEAR(bt.hankel[i], c["hsv"][static_cast<std::size_t>(i)].get<double>(), 1e-9 * bt.hankel[0]) << c["name"];
      expect_octave_response(bt.reduced, c, r);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 5);
}

TEST(BalancedTruncation, StablePartRefusesOrdersBelowTheKeptStates) {
  const auto& c = fixture()["cases"][3];
  ASSERT_EQ(c["name"], "c7_19_controller");
  const StateSpace g = system_of(c);
  EXPECT_THROW((void)balanced_truncation_stable_part(g, 2), std::invalid_argument);
  EXPECT_THROW((void)balanced_truncation_stable_part(g, 6), std::invalid_argument);
  // A stable system goes through unchanged: the same result as balanced_truncation.
  const StateSpace stable = system_of(fixture()["cases"][0]);
  const BalancedTruncation a = balanced_truncation_stable_part(stable, 3), b = balanced_truncation(stable, 3);
  EXPECT_EQ(a.unstable_states, 0);
  for (const double w : {0.3, 3.0})
    EXPECT_LT((frequency_response(a.reduced, w) - frequency_response(b.reduced, w)).norm(), 1e-10);
}

}  // namespace model_reduction_test
}  // namespace
}  // namespace servotwin::core
