#include "servotwin/core/transfer_function.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "core/reference_data.hpp"

namespace servotwin::core {
namespace {

using Complex = std::complex<double>;
using test::kInf;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

using test::tf;

TransferFunction from_case(const nlohmann::json& c) {
  return tf(c.at("num").get<std::vector<double>>(), c.at("den").get<std::vector<double>>());
}

// Thesis Table 3.4 (PID, x axis) and Table 3.3 (P-PI, x axis) closed-loop coefficients.
TransferFunction thesis_pid_tracking() { return tf({190.10, 44356.23, 316830.21}, {1.0, 192.65, 44356.23, 316830.21}); }
TransferFunction thesis_ppi_tracking() { return tf({11106.33, 1527104.87}, {1.0, 372.76, 62009.83, 1527104.87}); }

double relative_error(Complex a, Complex b) { return std::abs(a - b) / std::abs(b); }

TEST(TransferFunction, RejectsZeroAndNonFiniteDenominators) {
  EXPECT_THROW(tf({1.0}, {0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(tf({1.0}, {}), std::invalid_argument);
  EXPECT_THROW(tf({std::nan("")}, {1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(tf({1.0}, {1.0, kInf}), std::invalid_argument);
  EXPECT_NO_THROW(tf({}, {1.0, 1.0}));  // the zero transfer function is fine
}

TEST(TransferFunction, EvaluatesTheRationalFunction) {
  const TransferFunction g = tf({2.0, 3.0}, {1.0, 4.0, 5.0});
  for (Complex s : {Complex(0.3, -0.2), Complex(-2.0, 7.0), Complex(150.0, 1e3), Complex(0.0, 1e6)}) {
    const Complex expected = (2.0 * s + 3.0) / (s * s + 4.0 * s + 5.0);
    EXPECT_LE(relative_error(g(s), expected), 1e-14) << s;
    EXPECT_LE(relative_error(g.frequency_response(s.imag()), g(Complex(0.0, s.imag()))), 1e-14) << s;
  }
  EXPECT_EQ(tf({}, {1.0, 2.0})(Complex(1.0, 1.0)), Complex(0.0));
}

// Fixture: scipy.signal.freqs on a 121-point log grid, 0.1 .. 1e5 rad/s, for the thesis tracking
// TFs, a two-mass plant (resonance at 866 rad/s), an 8th-order Butterworth, a lead, an integrator
// and a non-monic TF. Both sides evaluate the same rational function with ~2n roundings, so they
// agree to a few hundred eps times the conditioning of the evaluation (at most ~1e2 here, near the
// lightly damped resonance): 1e-12 relative.
TEST(TransferFunction, FrequencyResponseMatchesScipyFreqs) {
  for (const auto& c : test::reference_section("frequency_response")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const TransferFunction g = from_case(c);
    const std::vector<double> omega = c.at("omega").get<std::vector<double>>();
    const std::vector<double> re = c.at("re").get<std::vector<double>>();
    const std::vector<double> im = c.at("im").get<std::vector<double>>();
    const std::vector<Complex> h = g.frequency_response(omega);
    ASSERT_EQ(h.size(), omega.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < omega.size(); ++i) worst = std::max(worst, relative_error(h[i], {re[i], im[i]}));
    EXPECT_LE(worst, 1e-12);
  }
}

TEST(TransferFunction, ButterworthMagnitudeClosedFormFromDcToExtremeFrequencies) {
  // |H(j w)| = 1 / sqrt(1 + (w / wc)^16): up to 1e39 rad/s, where w^8 alone would overflow a
  // naive evaluation (1e312) and w^-8 would be subnormal, although |H| = 1e-296 is a normal number.
  const auto& c = test::reference_case("frequency_response", "butterworth_8");
  const TransferFunction g = from_case(c);
  for (double w : {0.0, 1.0, 50.0, 100.0, 200.0, 1e4, 1e10, 1e39}) {
    const double ratio = w / 100.0;
    // For ratio > 1 the equivalent form r^-8 / sqrt(1 + r^-16) avoids overflowing the reference.
    const double expected = ratio <= 1.0 ? 1.0 / std::sqrt(1.0 + std::pow(ratio, 16.0))
                                         : std::pow(ratio, -8.0) / std::sqrt(1.0 + std::pow(ratio, -16.0));
    EXPECT_NEAR(std::abs(g.frequency_response(w)) / expected, 1.0, 1e-12) << w;
  }
  EXPECT_NEAR(std::abs(g(Complex(0.0, 1e39))) / std::abs(g.frequency_response(1e39)), 1.0, 1e-14);
}

TEST(TransferFunction, NegativeFrequenciesGiveTheConjugate) {
  const TransferFunction g = thesis_pid_tracking();
  for (double w : {0.5, 30.0, 2e3}) EXPECT_LE(relative_error(g.frequency_response(-w), std::conj(g.frequency_response(w))), 1e-15);
}

TEST(TransferFunction, ThesisPolesAndZerosMatchThePrintedTables) {
  // Wong 2007, Table 3.4 x axis "Actual": p1,2 33.00 Hz / 0.45, p3 1.17 Hz / 1.00; zeros 35.96 Hz
  // and 1.17 Hz (printed to 2 decimals, hence 0.006 tolerance on Hz and damping).
  const TransferFunction pid = thesis_pid_tracking();
  const auto poles = pid.poles();
  ASSERT_EQ(poles.size(), 3U);
  const ModalInfo p3 = modal_info(poles[0]);  // ascending modulus: the slow real pole first
  const ModalInfo p1 = modal_info(poles[1]);
  EXPECT_NEAR(p3.freq_hz, 1.17, 0.006);
  EXPECT_EQ(p3.zeta, 1.0);
  EXPECT_NEAR(p1.freq_hz, 33.00, 0.006);
  EXPECT_NEAR(p1.zeta, 0.45, 0.006);
  EXPECT_EQ(poles[2], std::conj(poles[1]));
  const auto zeros = pid.zeros();
  ASSERT_EQ(zeros.size(), 2U);
  EXPECT_NEAR(modal_info(zeros[0]).freq_hz, 1.17, 0.006);
  EXPECT_NEAR(modal_info(zeros[1]).freq_hz, 35.96, 0.006);

  // Table 3.3 x axis "Actual": p1,2 36.26 Hz / 0.75, p3 4.68 Hz; z3 21.88 Hz.
  const TransferFunction ppi = thesis_ppi_tracking();
  const auto pp = ppi.poles();
  ASSERT_EQ(pp.size(), 3U);
  EXPECT_NEAR(modal_info(pp[0]).freq_hz, 4.68, 0.006);
  EXPECT_NEAR(modal_info(pp[1]).freq_hz, 36.26, 0.006);
  EXPECT_NEAR(modal_info(pp[1]).zeta, 0.75, 0.006);
  ASSERT_EQ(ppi.zeros().size(), 1U);
  EXPECT_NEAR(modal_info(ppi.zeros()[0]).freq_hz, 21.88, 0.006);
}

TEST(TransferFunction, DcGainIsTheLimitAtZero) {
  EXPECT_NEAR(thesis_pid_tracking().dc_gain(), 1.0, 1e-15);  // a3 / a3: unit static tracking
  EXPECT_EQ(tf({2.0, 3.0}, {4.0, 5.0, 6.0}).dc_gain(), 0.5);
  EXPECT_EQ(tf({1.0}, {1.0, 0.0}).dc_gain(), kInf);             // integrator
  EXPECT_EQ(tf({-1.0}, {2.0, 0.0}).dc_gain(), -kInf);
  EXPECT_EQ(tf({1.0, 0.0}, {1.0, 1.0, 0.0}).dc_gain(), 1.0);    // s/(s^2+s) = 1/(s+1)
  EXPECT_EQ(tf({1.0, 0.0}, {1.0, 1.0}).dc_gain(), 0.0);         // differentiator
  EXPECT_EQ(tf({}, {1.0, 0.0}).dc_gain(), 0.0);
}

TEST(TransferFunction, ProperAndNormalized) {
  EXPECT_TRUE(tf({1.0, 2.0}, {1.0, 3.0}).is_proper());
  EXPECT_TRUE(tf({}, {1.0}).is_proper());
  EXPECT_FALSE(tf({1.0, 0.0, 0.0}, {1.0, 3.0}).is_proper());
  const TransferFunction n = tf({2.0, 3.0}, {4.0, 5.0, 6.0}).normalized();
  EXPECT_EQ(n.den(), Polynomial({1.0, 1.25, 1.5}));
  EXPECT_EQ(n.num(), Polynomial({0.5, 0.75}));
}

TEST(TransferFunction, FeedbackOfAnIntegratorIsAFirstOrderLag) {
  // Closed form: (1/s) / (1 + 1/s) = 1/(s+1).
  const TransferFunction loop = feedback(tf({1.0}, {1.0, 0.0}), tf({1.0}, {1.0}));
  EXPECT_EQ(loop.num(), Polynomial({1.0}));
  EXPECT_EQ(loop.den(), Polynomial({1.0, 1.0}));
  // Positive feedback: (1/s) / (1 - 1/s) = 1/(s-1).
  EXPECT_EQ(feedback(tf({1.0}, {1.0, 0.0}), tf({1.0}, {1.0}), +1).den(), Polynomial({1.0, -1.0}));
}

TEST(TransferFunction, FeedbackMatchesTheLoopEquationPointwise) {
  // P-PI style check: plant K/(s(Js+B)) with a PI velocity loop and unity position feedback.
  const TransferFunction plant = tf({2.5}, {0.01, 0.2, 0.0});
  const TransferFunction controller = tf({30.0, 400.0}, {1.0, 0.0});
  const TransferFunction sensor = tf({1.0}, {1e-3, 1.0});
  const TransferFunction forward = series(controller, plant);
  const TransferFunction loop = feedback(forward, sensor);
  for (double w : {0.1, 5.0, 80.0, 3e3}) {
    const Complex s(0.0, w);
    const Complex g = controller(s) * plant(s);
    EXPECT_LE(relative_error(forward(s), g), 1e-13);
    EXPECT_LE(relative_error(loop(s), g / (1.0 + g * sensor(s))), 1e-12);
    EXPECT_LE(relative_error(parallel(plant, controller)(s), plant(s) + controller(s)), 1e-13);
  }
}

TEST(TransferFunction, FeedbackRejectsBadSignAndSingularLoops) {
  const TransferFunction one = tf({1.0}, {1.0});
  EXPECT_THROW((void)feedback(one, one, 0), std::invalid_argument);
  EXPECT_THROW((void)feedback(one, one, 2), std::invalid_argument);
  EXPECT_THROW((void)feedback(one, one, +1), std::invalid_argument);  // 1 - 1 = 0
}

TEST(LogSpace, EndpointsAndConstantRatio) {
  const std::vector<double> w = log_space(0.1, 1e5, 61);
  ASSERT_EQ(w.size(), 61U);
  EXPECT_EQ(w.front(), 0.1);
  EXPECT_EQ(w.back(), 1e5);
  for (std::size_t i = 1; i < w.size(); ++i) EXPECT_NEAR(w[i] / w[i - 1], std::pow(10.0, 0.1), 1e-13);
  // numpy.logspace(-1, 5, 121) is the grid of the fixture.
  const auto& c = test::reference_case("frequency_response", "integrator");
  const std::vector<double> grid = c.at("omega").get<std::vector<double>>();
  const std::vector<double> ours = log_space(0.1, 1e5, grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i) EXPECT_NEAR(ours[i] / grid[i], 1.0, 1e-14);
}

TEST(LogSpace, DegenerateAndInvalidArguments) {
  EXPECT_TRUE(log_space(1.0, 10.0, 0).empty());
  EXPECT_EQ(log_space(3.0, 10.0, 1), std::vector<double>{3.0});
  EXPECT_EQ(log_space(10.0, 1.0, 2), (std::vector<double>{10.0, 1.0}));  // descending is allowed
  EXPECT_THROW((void)log_space(0.0, 10.0, 5), std::invalid_argument);
  EXPECT_THROW((void)log_space(1.0, -10.0, 5), std::invalid_argument);
  EXPECT_THROW((void)log_space(1.0, kInf, 5), std::invalid_argument);
  EXPECT_THROW((void)log_space(std::nan(""), 1.0, 5), std::invalid_argument);
}

TEST(ModalInfo, ContinuousRoots) {
  const ModalInfo m = modal_info({-3.0, 4.0});
  EXPECT_DOUBLE_EQ(m.omega_rad_s, 5.0);
  EXPECT_DOUBLE_EQ(m.freq_hz, 5.0 / kTwoPi);
  EXPECT_DOUBLE_EQ(m.zeta, 0.6);
  EXPECT_EQ(m.root, Complex(-3.0, 4.0));
  EXPECT_EQ(modal_info({-2.0, 0.0}).zeta, 1.0);
  EXPECT_EQ(modal_info({2.0, 0.0}).zeta, -1.0);
  EXPECT_EQ(modal_info({0.0, 7.0}).zeta, 0.0);
  const ModalInfo origin = modal_info({0.0, 0.0});
  EXPECT_EQ(origin.zeta, 1.0);
  EXPECT_EQ(origin.omega_rad_s, 0.0);
}

TEST(ModalInfo, DiscreteRootsMapThroughTheLogarithm) {
  const double ts = 1e-3;
  const Complex s(-92.64, 185.5);
  const ModalInfo m = modal_info_discrete(std::exp(s * ts), ts);  // z = exp(s ts) maps back to s
  EXPECT_LE(std::abs(m.root - s), 1e-10 * std::abs(s));
  EXPECT_NEAR(m.zeta, modal_info(s).zeta, 1e-12);
  // z = -0.5: s = ln(0.5)/ts + j pi/ts (the Nyquist frequency).
  const ModalInfo nyquist = modal_info_discrete({-0.5, 0.0}, ts);
  EXPECT_NEAR(nyquist.root.real(), std::log(0.5) / ts, 1e-9);
  EXPECT_NEAR(nyquist.root.imag(), std::numbers::pi / ts, 1e-9);
  const ModalInfo delay = modal_info_discrete({0.0, 0.0}, ts);
  EXPECT_EQ(delay.omega_rad_s, kInf);
  EXPECT_EQ(delay.freq_hz, kInf);
  EXPECT_EQ(delay.zeta, 1.0);
  EXPECT_EQ(modal_info_discrete({1.0, 0.0}, ts).zeta, 1.0);  // integrator: s = 0
}

}  // namespace
}  // namespace servotwin::core
