// State-space algebra (series, parallel, feedback, append, lft_lower), dc_gain,
// to_transfer_function, discretize_tustin and frequency responses.
//
// Expected values: tests/data/core/control_reference.json from
// tools/reference/core_control_reference.py (scipy.signal.ss2tf / cont2discrete, numpy LAPACK
// solves, and interconnection responses assembled from component responses by complex matrix
// algebra), plus closed forms (the prewarp identity, SISO transfer-function algebra of
// core::TransferFunction, similarity invariance).

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/reference_data.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace servotwin::core {
namespace {

using Complex = std::complex<double>;
using test::control_reference;
using test::reference_system;
using test::system_from;
using test::to_matrix;

Eigen::MatrixXcd complex_matrix(const nlohmann::json& rows) {
  Eigen::MatrixXcd m(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(rows.front().size()));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      const auto& v = rows[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      m(i, j) = Complex(v.at(0).get<double>(), v.at(1).get<double>());
    }
  return m;
}

double relative_difference(const Eigen::MatrixXcd& a, const Eigen::MatrixXcd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return std::numeric_limits<double>::infinity();
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

/// x -> T x with T = diag(scales): same transfer matrix, states in other units.
StateSpace rescale_states(const StateSpace& s, const Eigen::VectorXd& scales) {
  return StateSpace{scales.asDiagonal() * s.A * scales.cwiseInverse().asDiagonal(), scales.asDiagonal() * s.B,
                    s.C * scales.cwiseInverse().asDiagonal(), s.D};
}

StateSpace siso(const TransferFunction& g) { return to_state_space(g); }

// ---- frequency response ------------------------------------------------------------------------

TEST(StateSpaceFrequencyResponse, MatchesDirectLapackSolve) {
  for (const auto& c : control_reference().at("freqresp")) {
    const std::string name = c.at("system");
    const StateSpace sys = reference_system(name);
    FrequencyResponseEvaluator evaluator(sys);
    for (std::size_t k = 0; k < c.at("omega").size(); ++k) {
      const double w = c.at("omega")[k].get<double>();
      const Eigen::MatrixXcd expected = complex_matrix(c.at("G")[k]);
      SCOPED_TRACE(name + " omega " + std::to_string(w));
      EXPECT_LT(relative_difference(frequency_response(sys, w), expected), 1e-12);
      EXPECT_LT(relative_difference(evaluator(Complex(0.0, w)), expected), 1e-12);
      for (Eigen::Index i = 0; i < sys.outputs(); ++i)
        for (Eigen::Index j = 0; j < sys.inputs(); ++j)
          EXPECT_LT(std::abs(frequency_response(sys, w, i, j) - expected(i, j)), 1e-12 * expected.cwiseAbs().maxCoeff());
    }
  }
}

TEST(StateSpaceFrequencyResponse, AgreesWithTransferFunctionEvaluation) {
  // The controller-canonical realization of a TF has the TF's response (TransferFunction evaluates
  // the polynomials directly: an independent computation).
  const TransferFunction g(Polynomial{3.0, 0.5, 40.0}, Polynomial{1.0, 0.8, 25.0, 4.0, 30.0});
  const StateSpace s = siso(g);
  for (const double w : {0.0, 0.3, 1.0, 4.9, 5.0, 17.0, 1e3}) {
    const Complex expected = g.frequency_response(w);
    EXPECT_LT(std::abs(frequency_response(s, w, 0, 0) - expected), 1e-13 * std::abs(expected)) << w;
  }
}

TEST(StateSpaceFrequencyResponse, ZeroStateSystemIsItsFeedthrough) {
  const StateSpace gain{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 2), Eigen::MatrixXd(1, 0), Eigen::MatrixXd{{2.0, -3.0}}};
  const Eigen::MatrixXcd g = frequency_response(gain, 5.0);
  EXPECT_EQ(g(0, 0), Complex(2.0, 0.0));
  EXPECT_EQ(g(0, 1), Complex(-3.0, 0.0));
}

TEST(StateSpaceFrequencyResponse, RejectsBadArguments) {
  const StateSpace s = reference_system("two_mass");
  EXPECT_THROW((void)frequency_response(s, std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW((void)frequency_response(s, 1.0, 2, 0), std::invalid_argument);
  EXPECT_THROW((void)frequency_response(s, 1.0, 0, 1), std::invalid_argument);
  StateSpace bad = s;
  bad.B = Eigen::MatrixXd::Zero(2, 1);
  EXPECT_THROW((void)frequency_response(bad, 1.0), std::invalid_argument);
}

// ---- interconnections ----------------------------------------------------------------------------

struct InterconnectFixture {
  const nlohmann::json& c = control_reference().at("interconnect");
  StateSpace sys(const std::string& name) const { return system_from(c.at("systems").at(name)); }
  void expect_responses(const StateSpace& result, const std::string& key) const {
    for (std::size_t k = 0; k < c.at("omega").size(); ++k) {
      const double w = c.at("omega")[k].get<double>();
      EXPECT_LT(relative_difference(frequency_response(result, w), complex_matrix(c.at(key)[k])), 1e-12)
          << key << " omega " << w;
    }
  }
};

TEST(StateSpaceAlgebra, SeriesParallelAppendMatchMatrixAlgebraOfResponses) {
  const InterconnectFixture f;
  const StateSpace g = f.sys("g"), h = f.sys("h"), a2 = f.sys("a2");
  const StateSpace s = series(g, a2);  // y = a2(g(u))
  EXPECT_EQ(s.states(), g.states() + a2.states());
  EXPECT_EQ(s.inputs(), 2);
  EXPECT_EQ(s.outputs(), 3);
  f.expect_responses(s, "series_g_a2");
  f.expect_responses(parallel(g, h), "parallel_g_h");
  const StateSpace app = append(g, h);
  EXPECT_EQ(app.inputs(), 4);
  EXPECT_EQ(app.outputs(), 4);
  f.expect_responses(app, "append_g_h");
}

TEST(StateSpaceAlgebra, MimoFeedbackMatchesClosedLoopFormula) {
  const InterconnectFixture f;
  const StateSpace g = f.sys("g"), h = f.sys("h");  // h has D != 0: the algebraic part is exercised
  ASSERT_GT(h.D.norm(), 0.1);
  ASSERT_GT(g.D.norm(), 0.1);
  f.expect_responses(feedback(g, h), "feedback_negative");
  f.expect_responses(feedback(g, h, -1), "feedback_negative");
  f.expect_responses(feedback(g, h, +1), "feedback_positive");
}

TEST(StateSpaceAlgebra, LowerLftMatchesRedhefferFormula) {
  const InterconnectFixture f;
  const StateSpace p = f.sys("p"), k = f.sys("k");
  ASSERT_GT(std::abs(k.D(0, 0)), 0.05);
  const StateSpace cl = lft_lower(p, k, 1, 1);
  EXPECT_EQ(cl.states(), p.states() + k.states());
  EXPECT_EQ(cl.inputs(), 2);
  EXPECT_EQ(cl.outputs(), 2);
  f.expect_responses(cl, "lft_lower_p_k");
}

TEST(StateSpaceAlgebra, SisoLoopAgreesWithTransferFunctionAlgebra) {
  // Plant with integrator and a biproper lead controller: closed-loop poles and response from
  // the state-space path (feedback, then to_transfer_function) against the polynomial algebra of
  // TransferFunction (series/feedback: products and sums of polynomials).
  const TransferFunction plant(Polynomial{40.0}, Polynomial{1.0, 6.0, 0.0});
  const TransferFunction lead(Polynomial{2.0, 6.0}, Polynomial{1.0, 20.0});
  const TransferFunction expected = feedback(series(lead, plant), TransferFunction(Polynomial{1.0}, Polynomial{1.0}));
  const StateSpace unity{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Ones(1, 1)};
  const StateSpace loop = feedback(series(siso(lead), siso(plant)), unity);
  const TransferFunction computed = to_transfer_function(loop, 0, 0);
  for (const double w : {0.0, 0.5, 3.0, 10.0, 100.0}) {
    const Complex e = expected.frequency_response(w);
    EXPECT_LT(std::abs(computed.frequency_response(w) - e), 1e-12 * std::abs(e)) << w;
    EXPECT_LT(std::abs(frequency_response(loop, w, 0, 0) - e), 1e-12 * std::abs(e)) << w;
  }
  const std::vector<Complex> poles = computed.poles(), expected_poles = expected.poles();
  ASSERT_EQ(poles.size(), expected_poles.size());
  for (std::size_t i = 0; i < poles.size(); ++i) EXPECT_LT(std::abs(poles[i] - expected_poles[i]), 1e-12 * std::abs(expected_poles[i]));
}

TEST(StateSpaceAlgebra, AlgebraicLoopsAreRejected) {
  const StateSpace unity{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Ones(1, 1)};
  // u = r + y, y = u: I - Dg Dh = 0.
  try {
    (void)feedback(unity, unity, +1);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("algebraic loop"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW((void)feedback(unity, unity, -1));  // 1 + 1 = 2: well posed
  // LFT with D22 DK = 1.
  StateSpace p{Eigen::MatrixXd::Identity(1, 1) * -1.0, Eigen::MatrixXd::Ones(1, 2), Eigen::MatrixXd::Ones(2, 1),
               Eigen::MatrixXd{{0.0, 0.0}, {0.0, 2.0}}};
  const StateSpace k{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Constant(1, 1, 0.5)};
  EXPECT_THROW((void)lft_lower(p, k, 1, 1), std::invalid_argument);
  p.D(1, 1) = 1.0;
  EXPECT_NO_THROW((void)lft_lower(p, k, 1, 1));
}

TEST(StateSpaceAlgebra, ShapeErrors) {
  const InterconnectFixture f;
  const StateSpace g = f.sys("g"), a2 = f.sys("a2"), p = f.sys("p"), k = f.sys("k");
  EXPECT_THROW((void)series(a2, g), std::invalid_argument);  // a2 has 3 outputs, g 2 inputs
  EXPECT_THROW((void)parallel(g, a2), std::invalid_argument);
  EXPECT_THROW((void)feedback(g, a2), std::invalid_argument);
  EXPECT_THROW((void)feedback(g, f.sys("h"), 0), std::invalid_argument);
  EXPECT_THROW((void)lft_lower(p, k, 2, 1), std::invalid_argument);
  EXPECT_THROW((void)lft_lower(p, k, 1, 3), std::invalid_argument);
  EXPECT_THROW((void)lft_lower(p, k, 0, 1), std::invalid_argument);
  StateSpace nan = g;
  nan.A(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)append(nan, g), std::invalid_argument);
}

// ---- DC gain and transfer functions ---------------------------------------------------------------

TEST(StateSpaceDcGain, MatchesNumpySolveAndIsUnitInvariant) {
  for (const auto& c : control_reference().at("dcgain")) {
    const std::string name = c.at("system");
    const StateSpace sys = reference_system(name);
    const Eigen::MatrixXd expected = to_matrix(c.at("G0"));
    EXPECT_LT(test::max_relative_difference(dc_gain(sys), expected), 1e-12) << name;
    Eigen::VectorXd scales = Eigen::VectorXd::LinSpaced(sys.states(), -3.0, 3.0);
    scales = scales.unaryExpr([](double e) { return std::pow(10.0, e); });
    EXPECT_LT(test::max_relative_difference(dc_gain(rescale_states(sys, scales)), expected), 1e-12) << name;
  }
}

TEST(StateSpaceDcGain, PoleAtOriginIsADomainError) {
  const StateSpace integrator = siso(TransferFunction(Polynomial{1.0, 2.0}, Polynomial{1.0, 3.0, 0.0}));
  EXPECT_THROW((void)dc_gain(integrator), std::domain_error);
  const StateSpace gain{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Constant(1, 1, 4.0)};
  EXPECT_EQ(dc_gain(gain)(0, 0), 4.0);
}

/// Relative difference of polynomial coefficients (by power) against a scipy row, scaled by the
/// row's largest coefficient.
double coefficient_difference(const Polynomial& p, const std::vector<double>& descending) {
  const int n = static_cast<int>(descending.size()) - 1;
  double scale = 0.0, worst = 0.0;
  for (double v : descending) scale = std::max(scale, std::abs(v));
  for (int k = 0; k <= std::max(n, p.degree()); ++k) {
    const double ref = k <= n ? descending[static_cast<std::size_t>(n - k)] : 0.0;
    worst = std::max(worst, std::abs(p.coefficient_of_power(k) - ref));
  }
  return worst / scale;
}

/// Relative degree of a strictly proper channel: the first k with Markov parameter c A^(k-1) b
/// clearly nonzero (above 1e-8 of ||c|| ||A||^(k-1) ||b||): brute force on the plain matrices,
/// adequate for the fixture systems, whose Markov parameters are either exactly 0 or large.
int relative_degree(const StateSpace& sys, Eigen::Index out, Eigen::Index in) {
  if (sys.D(out, in) != 0.0) return 0;
  Eigen::VectorXd v = sys.B.col(in);
  double scale = v.norm() * sys.C.row(out).norm();
  for (int k = 1; k <= sys.states(); ++k) {
    if (std::abs(sys.C.row(out).dot(v)) > 1e-8 * scale) return k;
    v = sys.A * v;
    scale *= sys.A.norm();
  }
  return static_cast<int>(sys.states()) + 1;  // zero channel
}

TEST(StateSpaceToTransferFunction, MatchesScipySs2tf) {
  for (const auto& c : control_reference().at("ss2tf")) {
    const std::string name = c.at("system");
    const auto input = c.at("input").get<Eigen::Index>();
    const StateSpace sys = reference_system(name);
    const std::vector<double> den = c.at("den").get<std::vector<double>>();
    for (Eigen::Index out = 0; out < sys.outputs(); ++out) {
      SCOPED_TRACE(name + " input " + std::to_string(input) + " output " + std::to_string(out));
      const std::vector<double> num = c.at("num")[static_cast<std::size_t>(out)].get<std::vector<double>>();
      const TransferFunction g = to_transfer_function(sys, out, input);
      EXPECT_EQ(g.den().degree(), sys.states());
      EXPECT_EQ(g.den().leading(), 1.0);
      EXPECT_LT(coefficient_difference(g.den(), den), 1e-12);
      EXPECT_LT(coefficient_difference(g.num(), num), 1e-10);
      // Structural zeros: coefficients scipy leaves at rounding level are exact zeros here, so the
      // numerator degree is the true one, n - (relative degree of the channel).
      EXPECT_EQ(g.num().degree(), static_cast<int>(sys.states()) - relative_degree(sys, out, input));
      // And the TF reproduces the state-space response.
      for (const double w : {0.0, 1.0, 37.0, 870.0}) {
        const Complex e = frequency_response(sys, w, out, input);
        EXPECT_LT(std::abs(g.frequency_response(w) - e), 1e-9 * std::abs(e) + 1e-14) << w;
      }
    }
  }
}

TEST(StateSpaceToTransferFunction, KnownRelativeDegreesAndUnitInvariance) {
  // Two-mass drive: torque -> motor velocity has relative degree 1, -> load velocity 2.
  const StateSpace two_mass = reference_system("two_mass");
  EXPECT_EQ(to_transfer_function(two_mass, 0, 0).num().degree(), 2);
  EXPECT_EQ(to_transfer_function(two_mass, 1, 0).num().degree(), 1);
  const TransferFunction reference = to_transfer_function(two_mass, 1, 0);
  const StateSpace rescaled = rescale_states(two_mass, Eigen::Vector3d(1e3, 1.0, 1e-3));  // rad/s -> mrad/s ...
  const TransferFunction g = to_transfer_function(rescaled, 1, 0);
  EXPECT_EQ(g.num().degree(), 1);
  for (int k = 0; k <= 3; ++k) {
    EXPECT_NEAR(g.den().coefficient_of_power(k), reference.den().coefficient_of_power(k),
                1e-12 * std::abs(reference.den().coefficient_of_power(k))) << k;
    EXPECT_NEAR(g.num().coefficient_of_power(k), reference.num().coefficient_of_power(k),
                1e-10 * std::abs(reference.num().coefficient_of_power(1))) << k;
  }
  // Round trip through the controller canonical form.
  const TransferFunction tf(Polynomial{0.5, -2.0, 3.0}, Polynomial{2.0, 1.0, 7.0, 0.5});
  const TransferFunction back = to_transfer_function(siso(tf), 0, 0);
  const TransferFunction monic = tf.normalized();
  for (int k = 0; k <= 3; ++k) {
    EXPECT_NEAR(back.den().coefficient_of_power(k), monic.den().coefficient_of_power(k), 1e-14);
    EXPECT_NEAR(back.num().coefficient_of_power(k), monic.num().coefficient_of_power(k), 1e-14);
  }
  // Zero-state system and a channel that sees no state.
  const StateSpace gain{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Constant(1, 1, 2.5)};
  EXPECT_EQ(to_transfer_function(gain, 0, 0).num(), Polynomial{2.5});
  StateSpace blind = two_mass;
  blind.C.setZero();
  EXPECT_TRUE(to_transfer_function(blind, 0, 0).num().is_zero());
  EXPECT_THROW((void)to_transfer_function(two_mass, 2, 0), std::invalid_argument);
}

// ---- Tustin --------------------------------------------------------------------------------------

TEST(StateSpaceTustin, MatchesScipyBilinearAndPrewarpIdentity) {
  for (const auto& c : control_reference().at("tustin")) {
    const std::string name = c.at("system");
    const StateSpace sys = reference_system(name);
    const double ts = c.at("ts").get<double>();
    const std::optional<double> wp = c.at("prewarp").is_null() ? std::nullopt : std::optional<double>(c.at("prewarp").get<double>());
    SCOPED_TRACE(name + " ts " + std::to_string(ts) + (wp ? " prewarp " + std::to_string(*wp) : ""));
    const DiscreteStateSpace d = discretize_tustin(sys, ts, wp);
    EXPECT_EQ(d.ts, ts);
    EXPECT_LT(test::max_relative_difference(d.A, to_matrix(c.at("Ad"))), 1e-12);
    EXPECT_LT(test::max_relative_difference(d.B, to_matrix(c.at("Bd"))), 1e-12);
    EXPECT_LT(test::max_relative_difference(d.C, to_matrix(c.at("Cd"))), 1e-12);
    EXPECT_LT(test::max_relative_difference(d.D, to_matrix(c.at("Dd"))), 1e-12);
    for (std::size_t k = 0; k < c.at("omega").size(); ++k)
      EXPECT_LT(relative_difference(frequency_response(d, c.at("omega")[k].get<double>()), complex_matrix(c.at("Gd")[k])), 1e-11);
    if (wp) {
      // The defining property of prewarping: exact match of the responses at wp.
      EXPECT_LT(relative_difference(frequency_response(d, *wp), frequency_response(sys, *wp)), 1e-11);
      // ... which the plain bilinear map does not have (frequency warping).
      EXPECT_GT(relative_difference(frequency_response(discretize_tustin(sys, ts), *wp), frequency_response(sys, *wp)), 1e-4);
    }
  }
}

TEST(StateSpaceTustin, FirstOrderClosedForm) {
  // 1/(s + a) -> (T/2)(z + 1)/((1 + aT/2) z - (1 - aT/2)): Ad = (1 - aT/2)/(1 + aT/2).
  const double a = 3.0, ts = 0.1;
  const DiscreteStateSpace d = discretize_tustin(siso(TransferFunction(Polynomial{1.0}, Polynomial{1.0, a})), ts);
  EXPECT_NEAR(d.A(0, 0), (1.0 - a * ts / 2.0) / (1.0 + a * ts / 2.0), 1e-15);
  // DC is preserved exactly by the bilinear map (z = 1 <-> s = 0).
  EXPECT_NEAR(std::abs(frequency_response(d, 0.0)(0, 0)), 1.0 / a, 1e-15);
  // A static gain stays a static gain.
  const StateSpace gain{Eigen::MatrixXd(0, 0), Eigen::MatrixXd(0, 1), Eigen::MatrixXd(1, 0), Eigen::MatrixXd::Constant(1, 1, 4.0)};
  const DiscreteStateSpace dg = discretize_tustin(gain, ts, 5.0);
  EXPECT_EQ(dg.states(), 0);
  EXPECT_EQ(dg.D(0, 0), 4.0);
  EXPECT_EQ(frequency_response(dg, 1.0)(0, 0), Complex(4.0, 0.0));
}

TEST(StateSpaceTustin, RejectsBadArguments) {
  const StateSpace s = reference_system("two_mass");
  EXPECT_THROW((void)discretize_tustin(s, 0.0), std::invalid_argument);
  EXPECT_THROW((void)discretize_tustin(s, -1e-3), std::invalid_argument);
  EXPECT_THROW((void)discretize_tustin(s, 1e-3, std::numbers::pi / 1e-3), std::invalid_argument);
  EXPECT_THROW((void)discretize_tustin(s, 1e-3, 0.0), std::invalid_argument);
  // A pole at s = 2/T maps to z = infinity.
  const StateSpace unstable{Eigen::MatrixXd::Constant(1, 1, 20.0), Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Ones(1, 1),
                            Eigen::MatrixXd::Zero(1, 1)};
  EXPECT_THROW((void)discretize_tustin(unstable, 0.1), std::domain_error);
  EXPECT_NO_THROW((void)discretize_tustin(unstable, 0.05));
}

}  // namespace
}  // namespace servotwin::core
