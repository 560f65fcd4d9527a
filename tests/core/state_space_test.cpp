#include "servotwin/core/state_space.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/reference_data.hpp"

namespace servotwin::core {
namespace {

using Complex = std::complex<double>;
using test::max_relative_difference;
using test::reference_case;
using test::reference_section;
using test::to_matrix;

using test::tf;

StateSpace ss_from_case(const nlohmann::json& c) {
  return {to_matrix(c.at("A")), to_matrix(c.at("B")), to_matrix(c.at("C")), to_matrix(c.at("D"))};
}

/// C (sI - A)^-1 B + D of a SISO state-space model.
Complex ss_response(const StateSpace& sys, Complex s) {
  const Eigen::MatrixXcd si_minus_a = s * Eigen::MatrixXcd::Identity(sys.states(), sys.states()) - sys.A.cast<Complex>();
  const Eigen::VectorXcd x = si_minus_a.partialPivLu().solve(sys.B.cast<Complex>().col(0));
  return (sys.C.cast<Complex>() * x)(0) + sys.D(0, 0);
}

// ---- to_state_space --------------------------------------------------------------------------

// Fixture: scipy.signal.tf2ss. The realization is computed with the same operations in the same
// order (normalize by division, C = b[1:] - b0 a[1:]), so the matrices agree to the last bit; the
// 2-ulp margin of EXPECT_DOUBLE_EQ is not needed but harmless.
TEST(ToStateSpace, MatchesScipyTf2ssExactly) {
  for (const auto& c : reference_section("tf2ss")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const StateSpace ss = to_state_space(tf(c.at("num").get<std::vector<double>>(), c.at("den").get<std::vector<double>>()));
    const StateSpace ref = ss_from_case(c);
    for (const auto& [ours, theirs] : {std::pair{&ss.A, &ref.A}, {&ss.B, &ref.B}, {&ss.C, &ref.C}, {&ss.D, &ref.D}}) {
      ASSERT_EQ(ours->rows(), theirs->rows());
      ASSERT_EQ(ours->cols(), theirs->cols());
      for (Eigen::Index i = 0; i < ours->size(); ++i) EXPECT_DOUBLE_EQ(ours->data()[i], theirs->data()[i]);
    }
  }
}

TEST(ToStateSpace, RealizationReproducesTheTransferFunction) {
  // Independent of scipy: C (sI - A)^-1 B + D must equal num/den at any point.
  for (const TransferFunction& g : {tf({190.10, 44356.23, 316830.21}, {1.0, 192.65, 44356.23, 316830.21}),
                                    tf({2.0, 20.0}, {1.0, 100.0}), tf({3.0, -1.0, 2.0}, {2.0, 1.0, 4.0})}) {
    const StateSpace ss = to_state_space(g);
    for (Complex s : {Complex(0.0, 0.3), Complex(0.0, 50.0), Complex(-4.0, 900.0)})
      EXPECT_LE(std::abs(ss_response(ss, s) - g(s)), 1e-12 * std::abs(g(s))) << s;
  }
}

TEST(ToStateSpace, RejectsImproperTransferFunctions) {
  EXPECT_THROW((void)to_state_space(tf({1.0, 0.0, 0.0}, {1.0, 1.0})), std::invalid_argument);
}

// ---- discretize_zoh --------------------------------------------------------------------------

// Fixture: scipy.signal.cont2discrete(method="zoh") and the same exponential evaluated in 60-digit
// arithmetic ("Ad_exact", "Bd_exact"). Both double-precision results are within a few ulps of the
// exact one (scaling and squaring Pade in each, Eigen after balancing), so they agree with it to
// 4 eps and with each other to 8 eps, relative to the largest entry of each matrix.
TEST(DiscretizeZoh, MatchesScipyCont2discreteAndTheExtendedPrecisionExponential) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  for (const auto& c : reference_section("zoh")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const DiscreteStateSpace d = discretize_zoh(ss_from_case(c), c.at("ts").get<double>());
    EXPECT_EQ(d.ts, c.at("ts").get<double>());
    EXPECT_LE(max_relative_difference(d.A, to_matrix(c.at("Ad_exact"))), 4 * eps);
    EXPECT_LE(max_relative_difference(d.B, to_matrix(c.at("Bd_exact"))), 4 * eps);
    EXPECT_LE(max_relative_difference(d.A, to_matrix(c.at("Ad"))), 8 * eps);
    EXPECT_LE(max_relative_difference(d.B, to_matrix(c.at("Bd"))), 8 * eps);
    EXPECT_EQ(d.C, to_matrix(c.at("Cd")));
    EXPECT_EQ(d.D, to_matrix(c.at("Dd")));
  }
}

TEST(DiscretizeZoh, ClosedForms) {
  // Integrator: Ad = 1, Bd = ts.
  const DiscreteStateSpace i = discretize_zoh(to_state_space(tf({1.0}, {1.0, 0.0})), 0.01);
  EXPECT_DOUBLE_EQ(i.A(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(i.B(0, 0), 0.01);
  // Double integrator: Ad = [[1 T][0 1]], Bd = [T^2/2, T].
  const double t = 0.25;
  StateSpace di{Eigen::MatrixXd{{0.0, 1.0}, {0.0, 0.0}}, Eigen::MatrixXd{{0.0}, {1.0}}, Eigen::MatrixXd{{1.0, 0.0}},
                Eigen::MatrixXd::Zero(1, 1)};
  const DiscreteStateSpace d = discretize_zoh(di, t);
  EXPECT_DOUBLE_EQ(d.A(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(d.A(0, 1), t);
  EXPECT_DOUBLE_EQ(d.A(1, 0), 0.0);
  EXPECT_DOUBLE_EQ(d.A(1, 1), 1.0);
  EXPECT_DOUBLE_EQ(d.B(0, 0), t * t / 2.0);
  EXPECT_DOUBLE_EQ(d.B(1, 0), t);
  // First-order lag a/(s+a): Ad = exp(-a T), Bd = (1 - exp(-a T)) (realization x' = -a x + u, y = a x).
  const double a = 40.0;
  const DiscreteStateSpace f = discretize_zoh(to_state_space(tf({a}, {1.0, a})), 1e-3);
  EXPECT_NEAR(f.A(0, 0), std::exp(-a * 1e-3), 1e-15);
  EXPECT_NEAR(f.B(0, 0), (1.0 - std::exp(-a * 1e-3)) / a, 1e-17);
}

TEST(DiscretizeZoh, RejectsBadSamplePeriodsAndShapes) {
  const StateSpace g = to_state_space(tf({1.0}, {1.0, 1.0}));
  EXPECT_THROW((void)discretize_zoh(g, 0.0), std::invalid_argument);
  EXPECT_THROW((void)discretize_zoh(g, -1e-3), std::invalid_argument);
  EXPECT_THROW((void)discretize_zoh(g, std::nan("")), std::invalid_argument);
  EXPECT_THROW((void)discretize_zoh(g, std::numeric_limits<double>::infinity()), std::invalid_argument);
  StateSpace bad = g;
  bad.B = Eigen::MatrixXd::Zero(2, 1);
  EXPECT_THROW((void)discretize_zoh(bad, 1e-3), std::invalid_argument);
  bad = g;
  bad.D = Eigen::MatrixXd::Zero(1, 2);
  EXPECT_THROW((void)discretize_zoh(bad, 1e-3), std::invalid_argument);
  bad = g;
  bad.A(0, 0) = std::nan("");
  EXPECT_THROW((void)discretize_zoh(bad, 1e-3), std::invalid_argument);
  // exp(1e4) overflows: an error, not a matrix of infinities.
  EXPECT_THROW((void)discretize_zoh(to_state_space(tf({1.0}, {1.0, -1e4})), 1.0), std::invalid_argument);
}

// ---- simulation ------------------------------------------------------------------------------

// Fixture: scipy.signal.dlsim (3 states, 2 inputs, 2 outputs, nonzero x0). Same recursion, same
// operations up to summation order: agreement to 1e-13 relative to the largest output.
TEST(Simulate, MatchesScipyDlsim) {
  const auto& c = reference_case("dlsim", "mimo_3x2x2");
  const DiscreteStateSpace sys{to_matrix(c.at("A")), to_matrix(c.at("B")), to_matrix(c.at("C")), to_matrix(c.at("D")),
                               c.at("ts").get<double>()};
  const Eigen::MatrixXd y = simulate(sys, to_matrix(c.at("u")), test::to_vector(c.at("x0")));
  EXPECT_LE(max_relative_difference(y, to_matrix(c.at("y"))), 1e-13);
}

// Fixture: scipy.signal.lsim(interp=False) -- the two-mass plant (4 states, 2 outputs) under a
// switching torque with an initial shaft twist, and the thesis PID closed loop following a 10 mm
// move -- plus "y_exact", the same held-input recursion in 60-digit arithmetic. Ad is exact to an
// ulp per entry, but the two-mass plant has a rigid-body mode (eigenvalue 1 of Ad): per-entry ulp
// errors move that eigenvalue by ~1e-16 and the position drifts linearly over the 400 steps, to
// ~6e-13 of the peak value for ours and ~1e-13 for scipy's (measured). Hence 2e-12 against both.
TEST(SimulateZoh, MatchesScipyLsimWithHeldInputAndTheExtendedPrecisionRecursion) {
  for (const auto& c : reference_section("lsim")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Eigen::MatrixXd y =
        simulate_zoh(ss_from_case(c), to_matrix(c.at("u")), c.at("ts").get<double>(), test::to_vector(c.at("x0")));
    EXPECT_LE(max_relative_difference(y, to_matrix(c.at("y"))), 2e-12);
    EXPECT_LE(max_relative_difference(y, to_matrix(c.at("y_exact"))), 2e-12);
  }
}

// Fixture: scipy.signal.dstep of the zoh-discretized tf2ss realization.
TEST(StepResponse, MatchesScipyDstep) {
  for (const auto& c : reference_section("step")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const std::vector<double> expected = c.at("y").get<std::vector<double>>();
    const std::vector<double> y = step_response(tf(c.at("num").get<std::vector<double>>(), c.at("den").get<std::vector<double>>()),
                                                c.at("ts").get<double>(), expected.size());
    ASSERT_EQ(y.size(), expected.size());
    double worst = 0.0;
    double scale = 0.0;
    for (std::size_t k = 0; k < y.size(); ++k) {
      worst = std::max(worst, std::abs(y[k] - expected[k]));
      scale = std::max(scale, std::abs(expected[k]));
    }
    EXPECT_LE(worst, 1e-11 * scale);
  }
}

TEST(StepResponse, FirstOrderLagClosedForm) {
  // y(t) = K (1 - exp(-t / tau)) exactly at the samples (a step is its own zero-order hold).
  const double tau = 0.02;
  const double gain = 3.0;
  const double ts = 1e-3;
  const std::vector<double> y = step_response(tf({gain}, {tau, 1.0}), ts, 200);
  ASSERT_EQ(y.size(), 200U);
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double t = static_cast<double>(k) * ts;
    EXPECT_NEAR(y[k], gain * (1.0 - std::exp(-t / tau)), 1e-13) << k;
  }
}

TEST(StepResponse, RampOfAnIntegratorAndFeedthroughOfAStaticGain) {
  const std::vector<double> ramp = step_response(tf({2.0}, {1.0, 0.0}), 0.5, 5);
  for (std::size_t k = 0; k < ramp.size(); ++k) EXPECT_NEAR(ramp[k], 2.0 * 0.5 * static_cast<double>(k), 1e-15);
  EXPECT_EQ(step_response(tf({3.0}, {2.0}), 0.1, 3), (std::vector<double>{1.5, 1.5, 1.5}));
  EXPECT_TRUE(step_response(tf({1.0}, {1.0, 1.0}), 0.1, 0).empty());
  EXPECT_THROW((void)step_response(tf({1.0}, {1.0, 1.0}), 0.0, 3), std::invalid_argument);
}

TEST(Simulate, ChecksShapes) {
  const DiscreteStateSpace d = discretize_zoh(to_state_space(tf({1.0}, {1.0, 2.0, 1.0})), 0.1);
  EXPECT_THROW((void)simulate(d, Eigen::MatrixXd::Zero(10, 2)), std::invalid_argument);
  EXPECT_THROW((void)simulate(d, Eigen::MatrixXd::Zero(10, 1), Eigen::VectorXd::Zero(3)), std::invalid_argument);
  EXPECT_EQ(simulate(d, Eigen::MatrixXd::Zero(0, 1)).rows(), 0);
  DiscreteStateSpace bad = d;
  bad.C = Eigen::MatrixXd::Zero(1, 3);
  EXPECT_THROW((void)simulate(bad, Eigen::MatrixXd::Zero(10, 1)), std::invalid_argument);
  EXPECT_THROW((void)DiscreteSimulator{bad}, std::invalid_argument);
}

TEST(Simulate, LinearInInputAndInitialStateSoUnitsScale) {
  // Superposition, and with it unit invariance: simulating in mm gives 1000 x the result in m.
  const auto& c = reference_case("lsim", "two_mass_prbs");
  const DiscreteStateSpace d = discretize_zoh(ss_from_case(c), c.at("ts").get<double>());
  const Eigen::MatrixXd u = to_matrix(c.at("u"));
  const Eigen::VectorXd x0 = test::to_vector(c.at("x0"));
  const Eigen::MatrixXd y = simulate(d, u, x0);
  const Eigen::MatrixXd sum = simulate(d, u, Eigen::VectorXd::Zero(x0.size())) + simulate(d, Eigen::MatrixXd::Zero(u.rows(), 1), x0);
  // Not bit-exact (1000 is not a power of two, and the sum rounds differently): 400 steps of a
  // lightly damped resonance (zeta = 0.043) accumulate a few hundred roundings, hence 1e-12.
  EXPECT_LE(max_relative_difference(sum, y), 1e-12);
  EXPECT_LE(max_relative_difference(simulate(d, 1000.0 * u, 1000.0 * x0), 1000.0 * y), 1e-12);
}

TEST(DiscreteSimulator, StepByStepEqualsBatchSimulation) {
  const auto& c = reference_case("dlsim", "mimo_3x2x2");
  const DiscreteStateSpace sys{to_matrix(c.at("A")), to_matrix(c.at("B")), to_matrix(c.at("C")), to_matrix(c.at("D")),
                               c.at("ts").get<double>()};
  const Eigen::MatrixXd u = to_matrix(c.at("u"));
  const Eigen::VectorXd x0 = test::to_vector(c.at("x0"));
  const Eigen::MatrixXd batch = simulate(sys, u, x0);
  DiscreteSimulator sim(sys);
  EXPECT_EQ(sim.states(), 3);
  EXPECT_EQ(sim.inputs(), 2);
  EXPECT_EQ(sim.outputs(), 2);
  sim.set_state(x0);
  EXPECT_EQ(sim.state(), x0);
  for (Eigen::Index k = 0; k < u.rows(); ++k) {
    const double uk[2] = {u(k, 0), u(k, 1)};
    double yk[2] = {0.0, 0.0};
    sim.step(uk, yk);
    EXPECT_EQ(yk[0], batch(k, 0));
    EXPECT_EQ(yk[1], batch(k, 1));
  }
  sim.reset();
  EXPECT_EQ(sim.state(), Eigen::VectorXd::Zero(3));
  EXPECT_THROW(sim.set_state(Eigen::VectorXd::Zero(2)), std::invalid_argument);
}

TEST(DiscreteSimulator, SisoStepMatchesStepResponse) {
  const TransferFunction g = tf({190.10, 44356.23, 316830.21}, {1.0, 192.65, 44356.23, 316830.21});
  DiscreteSimulator sim(discretize_zoh(to_state_space(g), 1e-3));
  const std::vector<double> expected = step_response(g, 1e-3, 50);
  for (double e : expected) EXPECT_EQ(sim.step(1.0), e);
}

}  // namespace
}  // namespace servotwin::core
