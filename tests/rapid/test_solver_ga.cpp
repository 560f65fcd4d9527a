// The genetic algorithm of thesis section 4.2 against the exact solver: reproducible from its
// seed, always within the bounds, returns the best candidate of its history, and it never beats the certified global minimum. Expected values come from the exact solver, which
// test_solver_exact.cpp checks against an independent brute-force search.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "rapid/test_solver_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/rapid/solver.hpp"

namespace servotwin::rapid {
namespace {

using test::kTwoPi;

SolveOptions small_ga(std::uint64_t seed) {
  SolveOptions o;
  o.ga.population = 400;
  o.ga.generations = 60;
  o.ga.seed = seed;
  return o;
}

bool within(const Bounds& b, const Solution& s) {
  return s.p >= b.p_min && s.p <= b.p_max && s.wn >= b.wn_min && s.wn <= b.wn_max && s.zeta >= b.zeta_min &&
         s.zeta <= b.zeta_max;
}

TEST(SolverGa, SameSeedSameRunOtherSeedOtherRun) {
  const RegressionProblem pr = test::thesis_like_problem(test::thesis_pid_drive(), 11);
  Bounds b = default_bounds(1e-3);
  b.zeta_min = 0.6;
  const Solution a = solve(pr, Method::Ga, b, small_ga(5));
  const Solution again = solve(pr, Method::Ga, b, small_ga(5));
  const Solution other = solve(pr, Method::Ga, b, small_ga(6));
  EXPECT_EQ(a.theta, again.theta);
  ASSERT_EQ(a.history.size(), 60u);
  ASSERT_EQ(again.history.size(), a.history.size());
  for (std::size_t g = 0; g < a.history.size(); ++g) {
    EXPECT_EQ(a.history[g].objective, again.history[g].objective) << g;
    EXPECT_EQ(a.history[g].p, again.history[g].p) << g;
  }
  EXPECT_NE(a.history.front().objective, other.history.front().objective);
  EXPECT_EQ(a.seed, 5u);
  EXPECT_EQ(a.method, Method::Ga);
}

TEST(SolverGa, NeverBetterThanExactAndWithinTheBounds) {
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int close = 0;
  constexpr int kProblems = 40;
  for (int i = 0; i < kProblems; ++i) {
    SCOPED_TRACE(i);
    const double p = kTwoPi * (0.5 + 20.0 * u01(rng)), wn = kTwoPi * (10.0 + 80.0 * u01(rng));
    const RegressionProblem pr = test::random_problem(rng, p, wn, 0.2 + 1.2 * u01(rng), 0.02, i % 2 ? 0.9 : 0.0);
    Bounds b = default_bounds(1e-3);
    if (i % 3 == 0) b.zeta_min = 1.0;            // force an active damping bound
    if (i % 3 == 1) b.wn_max = 0.7 * wn;          // force an active frequency bound
    const Solution exact = solve(pr, Method::Exact, b);
    const Solution ga = solve(pr, Method::Ga, b, small_ga(static_cast<std::uint64_t>(i) + 1));
    ASSERT_TRUE(exact.certified);
    EXPECT_TRUE(within(b, ga));
    EXPECT_TRUE(ga.feasible);
    EXPECT_GE(ga.objective, exact.lower_bound * (1.0 - 1e-12));
    EXPECT_GE(ga.objective, exact.objective * (1.0 - 1e-9));
    // The returned point is the best candidate ever evaluated (a generation's pool best can be worse
    // than the last one's: crossover and mutation act on the surviving elite too, as in the thesis).
    double best = std::numeric_limits<double>::infinity();
    for (const auto& g : ga.history) best = std::min(best, g.objective);
    EXPECT_LE(ga.objective, best * (1.0 + 1e-9));  // the initial population may hold the best
    if (ga.objective <= exact.objective * 1.03) ++close;
  }
  // The thesis reports its GA within 2-3 % of the optimum; a small population gets there on most problems.
  EXPECT_GE(close, kProblems * 3 / 4);
}

TEST(SolverGa, ThesisSettingsReachTheExactOptimumClosely) {
  // Population 4000, rates 0.5 / 0.05, top 5 (thesis section 4.3), 100 generations.
  const RegressionProblem pr = test::thesis_like_problem(test::thesis_pid_drive(), 12);
  Bounds b = default_bounds(1e-3);
  b.zeta_min = 0.6;
  SolveOptions o;
  o.ga.generations = 100;
  const Solution ga = solve(pr, Method::Ga, b, o);
  const Solution exact = solve(pr, Method::Exact, b);
  EXPECT_GE(ga.objective, exact.objective * (1.0 - 1e-9));
  EXPECT_LE(ga.objective, exact.objective * 1.03);
  EXPECT_EQ(ga.history.size(), 100u);
}

TEST(SolverGa, BadSettingsAreReported) {
  const RegressionProblem pr = test::thesis_like_problem(test::thesis_pid_drive(), 11, 1e-3, 0.0, 1.0, 10);
  const Bounds b = default_bounds(1e-3);
  SolveOptions o;
  o.ga.population = 1;
  EXPECT_THAT([&] { (void)solve(pr, Method::Ga, b, o); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("ga.population")));
  o = SolveOptions{};
  o.ga.crossover_rate = 1.5;
  EXPECT_THAT([&] { (void)solve(pr, Method::Ga, b, o); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("ga.crossover_rate")));
  o = SolveOptions{};
  o.ga.elite = 5000;
  EXPECT_THAT([&] { (void)solve(pr, Method::Ga, b, o); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("ga.elite")));
}

}  // namespace
}  // namespace servotwin::rapid
