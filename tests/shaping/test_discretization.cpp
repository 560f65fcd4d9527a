// Discrete-time shapers (catalog C6.5, examples E16–E18). Expected values: the dissertation's
// printed numbers (E16, E17, E18) and tests/data/shaping/discrete_reference.json, written by
// tools/reference/shaping_discrete_reference.py (ZV4 from the C6.2 formulas, the decomposition by
// numpy.linalg.solve of the 2x2 pole condition, rounding, p1 grid search by brute force).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/shaping/discretization.hpp"
#include "servotwin/shaping/sensitivity.hpp"
#include "servotwin/shaping/zv4.hpp"

namespace servotwin::shaping {
namespace {

const nlohmann::json& reference() {
  static const nlohmann::json doc = test::load_fixture("discrete_reference.json");
  return doc;
}

Shaper continuous(const nlohmann::json& c) {
  return test::shaper_from(c, c.at("omega").get<double>(), c.at("zeta").get<double>());
}

const nlohmann::json& e18_case() { return reference().at("cases").at(0); }

std::string field_of(const auto& call) {
  try {
    call();
  } catch (const core::InputError& e) {
    return e.where().field;
  }
  return "<no error>";
}

TEST(Discretization, E16ShaperFromTheFixtureMatchesThePrintedOne) {
  // E16 (eq. 6.39): t = {0, 2.0945, 4.1890, 6.2835}, A = {0.1720, 0.3368, 0.3298, 0.1615}.
  const Shaper s = continuous(e18_case());
  const double t[] = {0, 2.0945, 4.1890, 6.2835}, a[] = {0.1720, 0.3368, 0.3298, 0.1615};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(s.times[static_cast<std::size_t>(i)], t[i], 6e-5);
    EXPECT_NEAR(s.amplitudes[static_cast<std::size_t>(i)], a[i], 6e-5);
  }
  // And the other helper's ZV4 design gives the same shaper.
  const Shaper z = zv4_shaper(1.0, 0.01, {0.5, 0.5, 0.0});
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(z.amplitudes[i], s.amplitudes[i], 1e-12);
}

TEST(Discretization, E18ExactDecompositionSevenPulsesZeroResidual) {
  const DiscreteShaper d = discretize(continuous(e18_case()), 0.5, DiscretizationMethod::Exact);
  // E18 (eq. 6.41): t = {0, 2, 2.5, 4, 4.5, 6, 6.5}, A = {0.1683, 0.2715, 0.0646, 0.2064, 0.1261, 0.071, 0.092}.
  const std::vector<std::size_t> delays{0, 4, 5, 8, 9, 12, 13};
  const double printed[] = {0.1683, 0.2715, 0.0646, 0.2064, 0.1261, 0.071, 0.092};
  ASSERT_EQ(d.delays, delays);
  double sum = 0.0;
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_NEAR(d.amplitudes[i], printed[i], i == 5 || i == 6 ? 6e-4 : 6e-5) << i;
    sum += d.amplitudes[i];
  }
  EXPECT_NEAR(sum, 1.0, 1e-15);
  EXPECT_LT(d.residual, 1e-14);
  EXPECT_GT(d.min_amplitude, 0.0);
  EXPECT_DOUBLE_EQ(d.duration(), 6.5);
  EXPECT_EQ(d.max_delay(), 13U);
}

TEST(Discretization, E17RoundingKeepsAmplitudesAndLeavesAboutNinePercent) {
  const Shaper s = continuous(e18_case());
  const DiscreteShaper d = discretize(s, 0.5, DiscretizationMethod::Round);
  // E17 (eq. 6.40): t = {0, 2, 4, 6.5}, A unchanged; residual 8.6–8.8 % (catalog [V]).
  EXPECT_EQ(d.delays, (std::vector<std::size_t>{0, 4, 8, 13}));
  for (std::size_t i = 0; i < 4; ++i) EXPECT_DOUBLE_EQ(d.amplitudes[i], s.amplitudes[i]);
  EXPECT_GT(d.residual, 0.086);
  EXPECT_LT(d.residual, 0.088);
  EXPECT_NEAR(d.residual, e18_case().at("round").at("residual").get<double>(), 1e-12);
}

TEST(Discretization, MatchesTheReferenceOnEveryCase) {
  for (const auto& c : reference().at("cases")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Shaper s = continuous(c);
    const double ts = c.at("ts").get<double>();
    for (const auto method : {DiscretizationMethod::Exact, DiscretizationMethod::Round}) {
      const auto& ref = c.at(discretization_method_name(method));
      const DiscreteShaper d = discretize(s, ts, method);
      ASSERT_EQ(d.delays, ref.at("delays").get<std::vector<std::size_t>>());
      const auto amps = ref.at("amplitudes").get<std::vector<double>>();
      for (std::size_t i = 0; i < amps.size(); ++i) EXPECT_NEAR(d.amplitudes[i], amps[i], 1e-12) << i;
      EXPECT_NEAR(d.residual, ref.at("residual").get<double>(), 1e-12);
      EXPECT_GT(d.min_amplitude, 0.0);  // positive pulses stay positive below half a period
    }
  }
}

TEST(Discretization, ExactResidualIsZeroAcrossSamplePeriods) {
  // Sweep ts up to just below half the damped period: the ZV condition must survive everywhere,
  // and the split of positive pulses stays positive (the sign argument in the header).
  const Shaper s = zv4_shaper(2 * std::numbers::pi * 7.0, 0.08, {-0.4, 0.35, 0.0});
  const double half_period = std::numbers::pi / (s.omega * std::sqrt(1 - s.zeta * s.zeta));
  for (double f = 0.001; f < 1.0; f *= 1.37) {
    const DiscreteShaper d = discretize(s, f * half_period, DiscretizationMethod::Exact);
    EXPECT_LT(d.residual, 1e-12) << f;
    EXPECT_GE(d.min_amplitude, 0.0) << f;
    EXPECT_LE(d.delays.size(), 7U);
  }
}

TEST(Discretization, MergedPulsesAreSummed) {
  // Case 4 of the fixture: T = 0.255 s < ts = 0.3 s, so neighbouring splits land on the same
  // samples; 4 pulses result, matching the reference.
  const auto& c = reference().at("cases").at(3);
  const DiscreteShaper d = discretize(continuous(c), c.at("ts").get<double>());
  EXPECT_EQ(d.delays, (std::vector<std::size_t>{0, 1, 2, 3}));
  // Rounding two pulses onto one sample adds them.
  Shaper two{"test", 1.0, 0.0, {0.0, 0.1, 0.2}, {0.5, 0.2, 0.3}};
  const DiscreteShaper r = discretize(two, 1.0, DiscretizationMethod::Round);
  EXPECT_EQ(r.delays, std::vector<std::size_t>{0});
  EXPECT_DOUBLE_EQ(r.amplitudes[0], 1.0);
}

TEST(Discretization, GridShaperIsUnchanged) {
  Shaper s = continuous(e18_case());
  const DiscreteShaper d = discretize(s, 0.5);
  const DiscreteShaper again = discretize(d.to_shaper(), 0.5);
  EXPECT_EQ(again.delays, d.delays);
  for (std::size_t i = 0; i < d.amplitudes.size(); ++i) EXPECT_NEAR(again.amplitudes[i], d.amplitudes[i], 1e-15);
}

TEST(Discretization, TimeUnitsDoNotMatter) {
  // The same shaper in ms instead of s (omega / 1000, times and ts * 1000): identical pulses.
  const Shaper s = continuous(reference().at("cases").at(1));
  Shaper ms = s;
  ms.omega = s.omega / 1000.0;
  for (double& t : ms.times) t *= 1000.0;
  const DiscreteShaper a = discretize(s, 0.004), b = discretize(ms, 4.0);
  ASSERT_EQ(a.delays, b.delays);
  for (std::size_t i = 0; i < a.amplitudes.size(); ++i) EXPECT_NEAR(a.amplitudes[i], b.amplitudes[i], 1e-12);
}

TEST(Discretization, SamplePeriodOverHalfADampedPeriodIsRejected) {
  const Shaper s = continuous(e18_case());
  const double half_period = std::numbers::pi / std::sqrt(1 - 0.01 * 0.01);
  EXPECT_EQ(field_of([&] { (void)discretize(s, half_period); }), "ts");
  EXPECT_EQ(field_of([&] { (void)discretize(s, 4.0); }), "ts");
  EXPECT_EQ(field_of([&] { (void)discretize(s, 4.0, DiscretizationMethod::Round); }), "ts");
  EXPECT_NO_THROW((void)discretize(s, 0.999 * half_period));
  try {
    (void)discretize(s, 4.0);
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("half the damped period"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("3.14"), std::string::npos) << e.what();
  }
}

TEST(Discretization, BadInputNamesTheField) {
  const Shaper good = continuous(e18_case());
  EXPECT_EQ(field_of([&] { (void)discretize(good, 0.0); }), "ts");
  EXPECT_EQ(field_of([&] { (void)discretize(good, std::nan("")); }), "ts");
  Shaper s = good;
  s.times.clear();
  s.amplitudes.clear();
  EXPECT_EQ(field_of([&] { (void)discretize(s, 0.5); }), "times");
  s = good;
  s.amplitudes.pop_back();
  EXPECT_EQ(field_of([&] { (void)discretize(s, 0.5); }), "amplitudes");
  s = good;
  s.times[0] = 0.1;
  EXPECT_EQ(field_of([&] { (void)discretize(s, 0.5); }), "times[0]");
  s = good;
  s.times[2] = s.times[1];
  EXPECT_EQ(field_of([&] { (void)discretize(s, 0.5); }), "times[2]");
  s = good;
  s.amplitudes[3] = INFINITY;
  EXPECT_EQ(field_of([&] { (void)discretize(s, 0.5); }), "amplitudes[3]");
  s = good;
  s.omega = 0.0;
  EXPECT_EQ(field_of([&] { (void)discretize(s, 0.5); }), "omega");
  s = good;
  s.zeta = 1.0;
  EXPECT_EQ(field_of([&] { (void)discretize(s, 0.5); }), "zeta");
  s = good;
  EXPECT_EQ(field_of([&] { (void)discretize(s, 1e-8); }), "ts");  // 6.5e8 samples of delay
  Shaper cancelling{"test", 1.0, 0.0, {0.0, 1.0}, {1.0, -1.0}};
  EXPECT_EQ(field_of([&] { (void)discretize(cancelling, 0.5); }), "amplitudes");
}

TEST(Discretization, NegativeInputAmplitudesAreKeptAndReported) {
  // A pulse train with a negative pulse (as LP synthesis may give): A = {0.6, -0.2, 0.6} at
  // t = {0, T, 2T} has IS(jw) = e^{-jwT} (1.2 cos wT - 0.2), zero at w = 1 for cos T = 1/6. The
  // decomposition is linear, so the negative pulse stays negative (min_amplitude reports it) and
  // zero vibration is preserved.
  const double T = std::acos(1.0 / 6.0);
  Shaper s{"test", 1.0, 0.0, {0.0, T, 2 * T}, {0.6, -0.2, 0.6}};
  EXPECT_LT(residual_vibration(s, 1.0, 0.0), 1e-15);
  const DiscreteShaper d = discretize(s, 0.3);
  EXPECT_LT(d.min_amplitude, 0.0);
  EXPECT_LT(d.residual, 1e-14);
}

TEST(Discretization, P1AdjustmentMatchesBruteForce) {
  for (const auto& g : reference().at("p1_grid")) {
    const GridP1 r = adjust_p1_to_grid(g.at("omega").get<double>(), g.at("zeta").get<double>(),
                                       g.at("p1").get<double>(), g.at("ts").get<double>());
    EXPECT_EQ(r.samples, g.at("samples").get<std::size_t>());
    EXPECT_NEAR(r.p1, g.at("p1_grid").get<double>(), 1e-12);
    EXPECT_NEAR(r.spacing, static_cast<double>(r.samples) * g.at("ts").get<double>(), 1e-15);
  }
}

TEST(Discretization, ZV4OnGridRoundsWithoutResidual) {
  // p1 adjusted: every pulse is on the grid, so rounding is exact (no residual) and needs only 4
  // taps where the exact decomposition of the unadjusted shaper needs 7.
  const double omega = 2 * std::numbers::pi * 10, zeta = 0.05, ts = 0.001;
  const Shaper s = zv4_on_grid(omega, zeta, {0.5, 0.3, 0.0}, ts);
  ASSERT_EQ(s.times.size(), 4U);
  const DiscreteShaper d = discretize(s, ts, DiscretizationMethod::Round);
  EXPECT_EQ(d.delays, (std::vector<std::size_t>{0, 33, 66, 99}));  // fixture: 33 samples per spacing
  EXPECT_LT(d.residual, 1e-12);
  // p1 = 0 with p3: p3 is dropped when the grid moves p1 off 0.
  const Shaper zvdd = zv4_on_grid(2 * std::numbers::pi * 23.7, 0.0, {0.0, 0.75, 0.75}, 0.0005);
  EXPECT_LT(discretize(zvdd, 0.0005, DiscretizationMethod::Round).residual, 1e-12);
}

TEST(Discretization, P1AdjustmentRejectsImpossibleRequests) {
  EXPECT_EQ(field_of([] { (void)adjust_p1_to_grid(1.0, 0.0, 1.5, 0.1); }), "p1");
  EXPECT_EQ(field_of([] { (void)adjust_p1_to_grid(-1.0, 0.0, 0.5, 0.1); }), "omega");
  EXPECT_EQ(field_of([] { (void)adjust_p1_to_grid(1.0, 0.0, 0.5, 0.0); }), "ts");
  // ts = 6 s > 5π/3 = 5.24 s (the longest ZV4 spacing at w = 1): no grid spacing exists.
  EXPECT_EQ(field_of([] { (void)adjust_p1_to_grid(1.0, 0.0, 0.5, 6.0); }), "ts");
  // ts = 1.5 s: only m = 1..3 qualify (p1 in [-1, 1]); the nearest to p1 = 1 is m = 1.
  const GridP1 r = adjust_p1_to_grid(1.0, 0.0, 1.0, 1.5);
  EXPECT_EQ(r.samples, 1U);
  EXPECT_NEAR(r.p1, 3 * (std::numbers::pi - 1.5) / (2 * std::numbers::pi), 1e-15);
}

}  // namespace
}  // namespace servotwin::shaping
