// The real-time shaper filter. References: the definition y[k] = Σ A_i u[k - d_i] evaluated by a
// direct convolution, the discrete shaper's own pulses (impulse response), and the residual
// vibration of a shaped step on a lightly damped mode simulated with core::discretize_zoh,
// compared with |IS(s)| from tools/reference/shaping_discrete_reference.py (where scipy's dlsim
// gives the same ratio).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include "fixture.hpp"
#include "malloc_counting.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/state_space.hpp"
#include "servotwin/shaping/realtime_shaper.hpp"

namespace servotwin::shaping {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace realtime_shaper_test {

const nlohmann::json& e18_case() {
  static const nlohmann::json doc = test::load_fixture("discrete_reference.json");
  return doc.at("cases").at(0);
}

DiscreteShaper e18(DiscretizationMethod method = DiscretizationMethod::Exact) {
  const auto& c = e18_case();
  return discretize(test::shaper_from(c, 1.0, 0.01), 0.5, method);
}

std::vector<double> convolve(const DiscreteShaper& s, const std::vector<double>& u, double before) {
  std::vector<double> y(u.size(), 0.0);
  for (std::size_t k = 0; k < u.size(); ++k)
    for (std::size_t i = 0; i < s.delays.size(); ++i)
      y[k] += s.amplitudes[i] * (k >= s.delays[i] ? u[k - s.delays[i]] : before);
  return y;
}

TEST(RealtimeShaper, ImpulseResponseIsThePulseTrain) {
  const DiscreteShaper s = e18();
  RealtimeShaper f(s);
  EXPECT_EQ(f.max_delay(), 13U);
  EXPECT_EQ(f.pulse_count(), 7U);
  EXPECT_EQ(f.buffer_size(), 16U);
  std::vector<double> h(40);
  for (std::size_t k = 0; k < h.size(); ++k) h[k] = f.step(k == 0 ? 1.0 : 0.0);
  std::size_t next = 0;
  for (std::size_t k = 0; k < h.size(); ++k) {
    if (next < s.delays.size() && s.delays[next] == k) {
      EXPECT_EQ(h[k], s.amplitudes[next]) << k;
      ++next;
    } else {
      EXPECT_EQ(h[k], 0.0) << k;
    }
  }
}

TEST(RealtimeShaper, StepResponseIsMonotoneAndReachesTheFinalValue) {
  RealtimeShaper f(e18());
  double previous = 0.0;
  for (int k = 0; k < 30; ++k) {
    const double y = f.step(2.5);
    EXPECT_GE(y, previous) << k;
    previous = y;
  }
  EXPECT_NEAR(previous, 2.5, 1e-15);
}

TEST(RealtimeShaper, MatchesDirectConvolutionOnRandomInput) {
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 3.0);
  for (const auto method : {DiscretizationMethod::Exact, DiscretizationMethod::Round}) {
    const DiscreteShaper s = e18(method);
    std::vector<double> u(1000);
    for (double& x : u) x = noise(rng);
    const double before = -1.25;
    const std::vector<double> expected = convolve(s, u, before);
    RealtimeShaper f(s, before);
    std::vector<double> y(u.size());
    EXPECT_EQ(f.process(u, y), u.size());
    for (std::size_t k = 0; k < u.size(); ++k) EXPECT_NEAR(y[k], expected[k], 1e-12) << k;
    // In place, after a reset to the same history, gives the same numbers.
    f.reset(before);
    std::vector<double> in_place = u;
    f.process(in_place, in_place);
    for (std::size_t k = 0; k < u.size(); ++k) EXPECT_EQ(in_place[k], y[k]) << k;
  }
}

TEST(RealtimeShaper, MultiAxisEqualsOneShaperPerAxis) {
  const DiscreteShaper s = e18();
  const std::vector<double> start{1.0, -2.0, 0.5};
  MultiAxisShaper multi(s, start);
  EXPECT_EQ(multi.axes(), 3U);
  std::vector<RealtimeShaper> single;
  for (const double x0 : start) single.emplace_back(s, x0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-10.0, 10.0);
  std::vector<double> in(3), out(3);
  for (int k = 0; k < 200; ++k) {
    for (double& x : in) x = value(rng);
    multi.step(in, out);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(out[i], single[i].step(in[i]));
  }
}

TEST(RealtimeShaper, StepAndProcessDoNotAllocate) {
  SKIP_WITHOUT_COUNTING();
  RealtimeShaper f(e18());
  MultiAxisShaper multi(e18(), std::vector<double>{0.0, 0.0});
  std::vector<double> in(256, 1.0), out(256), axes_in{1.0, 2.0}, axes_out(2);
  const std::size_t before = test_support::allocations();
  double sum = 0.0;
  for (int k = 0; k < 1000; ++k) sum += f.step(static_cast<double>(k));
  f.process(in, out);
  f.reset(3.0);
  multi.step(axes_in, axes_out);
  EXPECT_EQ(test_support::allocations(), before);
  EXPECT_GT(sum, 0.0);
}

// Modal coordinate z = y' - conj(s) (y - y_final) of the mode P(s) = w² / (s² + 2ζw s + w²) after
// a (shaped) step, simulated with a ZOH: a sum of delayed steps of a piecewise-constant input is
// exact at the samples.
std::complex<double> modal_coordinate(const std::vector<double>& u, double w, double zeta, double ts) {
  core::StateSpace mode;
  mode.A.resize(2, 2);
  mode.A << 0.0, 1.0, -w * w, -2.0 * zeta * w;
  mode.B.resize(2, 1);
  mode.B << 0.0, w * w;
  mode.C = Eigen::MatrixXd::Identity(2, 2);
  mode.D = Eigen::MatrixXd::Zero(2, 1);
  core::DiscreteSimulator sim(core::discretize_zoh(mode, ts));
  std::vector<double> y(2);
  for (const double x : u) sim.step(std::span<const double>(&x, 1), y);
  const std::complex<double> s{-zeta * w, w * std::sqrt(1 - zeta * zeta)};
  return y[1] - std::conj(s) * (y[0] - u.back());
}

TEST(RealtimeShaper, ShapedStepLeavesNoResidualVibrationOnTheMode) {
  const double w = 1.0, zeta = 0.01, ts = 0.5;
  std::vector<double> step(60, 1.0);
  const std::complex<double> unshaped = modal_coordinate(step, w, zeta, ts);
  for (const auto method : {DiscretizationMethod::Exact, DiscretizationMethod::Round}) {
    RealtimeShaper f(e18(method));
    std::vector<double> shaped(step.size());
    f.process(step, shaped);
    const double ratio = std::abs(modal_coordinate(shaped, w, zeta, ts)) / std::abs(unshaped);
    if (method == DiscretizationMethod::Exact) {
      EXPECT_LT(ratio, 1e-12);  // scipy dlsim: 2e-16
    } else {
      // |IS(s)| of the rounded shaper = 0.0937 (= e^{ζω t_n} · 8.78 %), scipy dlsim agrees.
      EXPECT_NEAR(ratio, e18_case().at("round").at("modal_ratio").get<double>(), 1e-10);
      EXPECT_NEAR(ratio, e18_case().at("round").at("modal_ratio_simulated").get<double>(), 1e-10);
    }
  }
}

TEST(RealtimeShaper, RejectsMalformedDiscreteShapers) {
  DiscreteShaper s = e18();
  s.delays.clear();
  s.amplitudes.clear();
  EXPECT_THROW(RealtimeShaper{s}, core::InputError);
  s = e18();
  s.delays[0] = 1;
  EXPECT_THROW(RealtimeShaper{s}, core::InputError);
  s = e18();
  s.delays[3] = s.delays[2];
  EXPECT_THROW(RealtimeShaper{s}, core::InputError);
  s = e18();
  s.amplitudes.pop_back();
  EXPECT_THROW(RealtimeShaper{s}, core::InputError);
  s = e18();
  s.amplitudes[1] = NAN;
  EXPECT_THROW(RealtimeShaper{s}, core::InputError);
  EXPECT_THROW(MultiAxisShaper(e18(), std::vector<double>{}), core::InputError);
}

}  // namespace realtime_shaper_test
}  // namespace
}  // namespace servotwin::shaping
