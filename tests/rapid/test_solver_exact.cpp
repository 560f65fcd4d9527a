// The exact solver against an independent brute force (60^3 / 40^3 grid over the bounds plus
// polishing, with its own elimination of theta2), on random, thesis-like and adversarial problems:
// never worse than the brute force, certified lower bound below it, Kuhn-Tucker conditions, equal
// to least squares when that is feasible, unit-free, and bounded in time on degenerate problems.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "rapid/test_solver_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/rapid/solver.hpp"
#include "servotwin/rapid/solver_detail.hpp"

namespace servotwin::rapid {
namespace {

using test::kTwoPi;

struct Case {
  RegressionProblem problem;
  Bounds bounds;
  std::string label;
};

/// Random problems: true poles anywhere in the default bounds, noise from 0.1 % to 20 %,
/// correlated or nearly collinear regressors, and bounds narrowed at random so that every
/// combination of active bounds occurs.
std::vector<Case> random_cases(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Bounds full = default_bounds(1e-3);
  auto log_uniform = [&](double lo, double hi) { return std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * u01(rng)); };
  std::vector<Case> cases;
  for (int i = 0; i < count; ++i) {
    const double p = log_uniform(2.0, 2500.0), wn = log_uniform(5.0, 2500.0), zeta = 0.1 + 2.4 * u01(rng);
    const double noise = std::array<double, 3>{1e-3, 2e-2, 0.2}[static_cast<std::size_t>(i % 3)];
    const double collinearity = std::array<double, 3>{0.0, 0.9, 0.999}[static_cast<std::size_t>((i / 3) % 3)];
    Case c{test::random_problem(rng, p, wn, zeta, noise, collinearity), full, "random " + std::to_string(i)};
    auto narrow = [&](double& lo, double& hi, bool log_scale) {
      if (u01(rng) < 0.35) {
        const double a = log_scale ? log_uniform(lo, hi) : lo + (hi - lo) * u01(rng);
        const double b = log_scale ? log_uniform(lo, hi) : lo + (hi - lo) * u01(rng);
        lo = std::min(a, b);
        hi = std::max(a, b);
      }
    };
    narrow(c.bounds.p_min, c.bounds.p_max, true);
    narrow(c.bounds.wn_min, c.bounds.wn_max, true);
    narrow(c.bounds.zeta_min, c.bounds.zeta_max, false);
    cases.push_back(std::move(c));
  }
  return cases;
}

/// The properties every exact solution must have, against the brute force.
void check_exact(const Case& c, int grid) {
  SCOPED_TRACE(c.label);
  const Solution exact = solve(c.problem, Method::Exact, c.bounds);
  const test::BruteForce brute = test::brute_force_minimum(c.problem, c.bounds, grid);
  const double f = exact.objective;
  const double y2 = c.problem.normal_equations().gamma;
  // The objective's own rounding (residual from the factor) and the certificate's tolerance.
  const double rounding = 1e-13 * std::sqrt(y2 * 2.0 * f) + 1e-12 * f;
  EXPECT_TRUE(exact.certified);
  EXPECT_TRUE(exact.feasible);
  EXPECT_LE(f, brute.objective + 1e-9 * f + rounding) << "brute force found a better point: p = " << brute.p
                                                      << ", wn = " << brute.wn << ", zeta = " << brute.zeta;
  EXPECT_LE(exact.lower_bound, brute.objective + rounding);
  EXPECT_LE(exact.lower_bound, f);
  EXPECT_LE(f - exact.lower_bound, 1e-9 * f + rounding);
  // Kuhn-Tucker: multipliers >= 0, gradient zero in the free variables (relative to f over the
  // variable's scale: d f / d ln p, d f / d ln wn, d f / d zeta).
  const std::array<double, 3> scale{exact.p, exact.wn, 1.0};
  // A stationary point is resolved only as far as f is: a gradient below sqrt(curvature x rounding
  // of f) changes f by less than its rounding (curvature in these units is of the order of f).
  const double grad_tol = 1e-6 * f + 4.0 * std::sqrt(f * rounding);
  for (const auto& a : exact.active) {
    const int j = a.name[0] == 'p' ? 0 : (a.name[0] == 'w' ? 1 : 2);
    EXPECT_GE(a.multiplier * scale[static_cast<std::size_t>(j)], -grad_tol) << a.name;
  }
  for (int j = 0; j < 3; ++j) {
    const char* prefix = j == 0 ? "p_" : (j == 1 ? "wn_" : "zeta_");
    const bool active = std::any_of(exact.active.begin(), exact.active.end(),
                                    [&](const ActiveBound& a) { return a.name.rfind(prefix, 0) == 0; });
    if (!active) {
      EXPECT_LE(std::abs(exact.gradient(j)) * scale[static_cast<std::size_t>(j)], grad_tol) << prefix;
    }
  }
  // Case 1 of Table 3.1: the unconstrained solution is feasible, so it is the answer.
  const Solution ls = solve(c.problem, Method::Ls, c.bounds);
  if (ls.feasible) {
    EXPECT_EQ(exact.theta, ls.theta);
    EXPECT_EQ(exact.kkt_case, "1: unconstrained");
  } else {
    EXPECT_NE(exact.kkt_case, "1: unconstrained");
  }
}

TEST(SolverExact, RandomProblemsAgainstBruteForce) {
  for (const Case& c : random_cases(200, 2024)) check_exact(c, 40);
}

TEST(SolverExact, ThesisLikeProblemsAgainstBruteForce) {
  // Table 4.1's PID drive (its real pole nearly cancelled by a zero, so p is weakly identified),
  // under bounds that make each kind of constraint active.
  const ModelCoefficients pid = test::thesis_pid_drive();
  const ModelCoefficients stiff = test::drive_from_poles(kTwoPi * 300.0, kTwoPi * 60.0, 0.7, 0.9, 800.0, -700.0);
  struct Variant {
    const char* label;
    Bounds bounds;
    const char* expected_case;
  };
  const Bounds d = default_bounds(1e-3);
  auto with = [&](auto change) {
    Bounds b = d;
    change(b);
    return b;
  };
  const std::vector<Variant> variants{
      {"default", d, "1: unconstrained"},
      {"zeta_min 0.6", with([](Bounds& b) { b.zeta_min = 0.6; }), "2: zeta = zeta_min"},
      {"zeta_max 0.3", with([](Bounds& b) { b.zeta_max = 0.3; }), "9: zeta = zeta_max"},
      {"wn_min 45 Hz", with([](Bounds& b) { b.wn_min = kTwoPi * 45; }), "3: wn = wn_min"},
      {"p_min 3 Hz", with([](Bounds& b) { b.p_min = kTwoPi * 3; }), "5: p = p_min"},
      {"wn_max 25 Hz", with([](Bounds& b) { b.wn_max = kTwoPi * 25; }), nullptr},
      {"p_max 0.5 Hz", with([](Bounds& b) { b.p_max = kTwoPi * 0.5; }), nullptr},
      {"narrow box", with([](Bounds& b) {
         b.p_min = kTwoPi * 5, b.p_max = kTwoPi * 6, b.wn_min = kTwoPi * 20, b.wn_max = kTwoPi * 22;
         b.zeta_min = 0.8, b.zeta_max = 0.9;
       }),
       nullptr},
  };
  for (std::uint64_t seed : {11u, 12u}) {
    const RegressionProblem pr = test::thesis_like_problem(pid, seed);
    for (const auto& v : variants) {
      check_exact({pr, v.bounds, std::string("pid ") + v.label}, 60);
      if (v.expected_case != nullptr) {
        EXPECT_EQ(solve(pr, Method::Exact, v.bounds).kkt_case, v.expected_case) << v.label;
      }
    }
    check_exact({test::thesis_like_problem(stiff, seed, 1e-4), with([](Bounds& b) { b.zeta_min = 0.9; }), "stiff"}, 60);
  }
}

TEST(SolverExact, FoldOfTheParametrizationIsFoundAndNamed) {
  // With wn <= 25 Hz the best fit of a 33 Hz pair uses three real poles, two of them equal: p is
  // a root of the quadratic factor, no bound is active, and Table 3.1 has no case for it.
  const RegressionProblem pr = test::thesis_like_problem(test::thesis_pid_drive(), 11);
  Bounds b = default_bounds(1e-3);
  b.wn_max = kTwoPi * 25;
  const Solution s = solve(pr, Method::Exact, b);
  EXPECT_THAT(s.kkt_case, testing::StartsWith("fold"));
  EXPECT_TRUE(s.active.empty());
  EXPECT_GT(s.zeta, 1.0);
  const double r1 = s.wn * (s.zeta - std::sqrt(s.zeta * s.zeta - 1.0));
  const double r2 = s.wn * (s.zeta + std::sqrt(s.zeta * s.zeta - 1.0));
  EXPECT_LT(std::min(std::abs(s.p - r1) / r1, std::abs(s.p - r2) / r2), 1e-4);
}

TEST(SolverExact, AdversarialProblems) {
  std::mt19937_64 rng(77);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Bounds d = default_bounds(1e-3);
  std::vector<Case> cases;
  // Nearly collinear x' and x_r', x'' and x_r'' (tracking error 1e-7 of the signal).
  for (int i = 0; i < 4; ++i) {
    Bounds b = d;
    b.zeta_min = 0.5 + 0.3 * i;
    cases.push_back({test::random_problem(rng, 30.0, 200.0, 0.4, 0.01, 1.0 - 1e-7), b, "collinear " + std::to_string(i)});
  }
  // A friction column of zeros.
  {
    Eigen::MatrixXd phi(100, kParameterCount);
    for (int i = 0; i < phi.rows(); ++i) {
      for (int j = 0; j < kParameterCount; ++j) phi(i, j) = gauss(rng) * std::pow(10.0, j % 3);
    }
    phi.col(6).setZero();
    Vector8 theta;
    theta << theta1_from_poles(20.0, 150.0, 0.3), 1.0, 0.01, 1e-4, 0.0, 0.02;
    Eigen::VectorXd y = phi * theta;
    for (int i = 0; i < y.size(); ++i) y(i) += 0.05 * gauss(rng);
    Bounds b = d;
    b.zeta_min = 0.5;
    cases.push_back({test::problem_from_rows(phi, y, 1e-3), b, "zero PV column"});
  }
  // Normal equations of nearly dependent regressors, rounded like a text round trip: P looks
  // indefinite at the 1e-16 level.
  for (int i = 0; i < 3; ++i) {
    const RegressionProblem base = test::random_problem(rng, 50.0, 400.0, 1.3, 0.05, 1.0 - 1e-5);
    NormalEquations ne = base.normal_equations();
    for (int r = 0; r < kParameterCount; ++r) {
      for (int c = r + 1; c < kParameterCount; ++c) {
        const double v = ne.P(r, c) * (1.0 + 1e-15 * gauss(rng));
        ne.P(r, c) = ne.P(c, r) = v;
      }
    }
    Bounds b = d;
    b.wn_max = 300.0;
    cases.push_back({RegressionProblem::from_normal_equations(ne), b, "normal equations " + std::to_string(i)});
  }
  // Pole-zero cancellation in the data, p weakly identified, bounds forcing p off its optimum.
  {
    const ModelCoefficients c = test::drive_from_poles(8.0, 250.0, 0.5, 1.0, 300.0, -300.0);
    Bounds b = d;
    b.p_min = 40.0;
    b.zeta_max = 0.45;
    cases.push_back({test::thesis_like_problem(c, 5, 1e-3), b, "cancellation"});
  }
  // Bounds that fix variables (equal lower and upper bounds).
  {
    Bounds b = d;
    b.p_min = b.p_max = 30.0;
    b.zeta_min = b.zeta_max = 0.7;
    cases.push_back({test::random_problem(rng, 10.0, 100.0, 0.3, 0.05), b, "fixed p and zeta"});
  }
  for (const Case& c : cases) check_exact(c, 60);
}

TEST(SolverExact, DegenerateDataNeverHangs) {
  // y = 0: every model fits except for the scale; theta1 columns zero: f is constant.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::MatrixXd phi(50, kParameterCount);
  for (int i = 0; i < phi.rows(); ++i) {
    for (int j = 0; j < kParameterCount; ++j) phi(i, j) = gauss(rng);
  }
  // With y = 0 the objective is still positive: theta1 cannot vanish inside the bounds (1/a2 is at
  // least 1/(wn_max^2 + 4 zeta_max p_max wn_max)), so the brute force is the reference.
  check_exact({test::problem_from_rows(phi, Eigen::VectorXd::Zero(50), 1e-3), default_bounds(1e-3), "y = 0"}, 40);
  Eigen::MatrixXd flat = phi;
  flat.leftCols(3).setZero();
  const Eigen::VectorXd y = flat.col(3) + 0.1 * flat.col(4);
  const Solution constant = solve(test::problem_from_rows(flat, y, 1e-3), Method::Exact, default_bounds(1e-3));
  EXPECT_TRUE(constant.certified);
  EXPECT_LE(constant.boxes, 10u);
  // A box budget stops the search with a warning and a valid (looser) lower bound.
  const RegressionProblem pr = test::thesis_like_problem(test::thesis_pid_drive(), 11);
  Bounds b = default_bounds(1e-3);
  b.wn_max = kTwoPi * 25;
  SolveOptions o;
  o.max_boxes = 20;
  const Solution capped = solve(pr, Method::Exact, b, o);
  EXPECT_FALSE(capped.certified);
  EXPECT_LE(capped.boxes, 22u);
  EXPECT_LE(capped.lower_bound, capped.objective);
  EXPECT_THAT(capped.warnings, testing::Contains(testing::HasSubstr("max_boxes")));
  const Solution full = solve(pr, Method::Exact, b);
  EXPECT_LE(capped.lower_bound, full.objective);
  EXPECT_LE(full.objective, capped.objective * (1.0 + 1e-12));
}

TEST(SolverExact, NothingDependsOnLengthUnits) {
  const ModelCoefficients c = test::thesis_pid_drive();
  const RegressionProblem mm = test::thesis_like_problem(c, 21, 1e-3, 0.0, 1.0, 30);
  const RegressionProblem m = test::thesis_like_problem(c, 21, 1e-3, 0.0, 1e-3, 30);
  for (const double zeta_min : {0.2, 0.6}) {
    Bounds b = default_bounds(1e-3);
    b.zeta_min = zeta_min;
    const Solution smm = solve(mm, Method::Exact, b), sm = solve(m, Method::Exact, b);
    EXPECT_EQ(smm.kkt_case, sm.kkt_case);
    EXPECT_NEAR(1e6 * sm.objective, smm.objective, 2e-9 * smm.objective);
    // The poles agree as far as f determines them (f is flat to 1e-9 over about 1e-4 in p).
    EXPECT_NEAR(sm.p, smm.p, 1e-3 * smm.p);
    EXPECT_NEAR(sm.wn, smm.wn, 1e-5 * smm.wn);
    EXPECT_NEAR(sm.zeta, smm.zeta, 1e-5);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(sm.theta(j), smm.theta(j), 1e-3 * std::abs(smm.theta(j)));
  }
}

TEST(SolverExact, BadInputIsReported) {
  const RegressionProblem pr = test::thesis_like_problem(test::thesis_pid_drive(), 11, 1e-3, 0.0, 1.0, 10);
  Bounds b = default_bounds(1e-3);
  b.zeta_min = -0.1;
  EXPECT_THAT([&] { (void)solve(pr, Method::Exact, b); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("bounds.zeta_min")));
  b = default_bounds(1e-3);
  b.wn_max = b.wn_min / 2;
  EXPECT_THAT([&] { (void)solve(pr, Method::Exact, b); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("bounds.wn_max")));
  b = default_bounds(1e-3);
  b.p_max = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)solve(pr, Method::Exact, b), core::InputError);
  EXPECT_THAT([&] { (void)solve(RegressionProblem{}, Method::Exact, default_bounds(1e-3)); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("no samples")));
  EXPECT_THAT([&] { (void)default_bounds(0.0); }, testing::ThrowsMessage<core::InputError>(testing::HasSubstr("ts")));
  EXPECT_THROW((void)default_bounds(10.0), core::InputError);  // Nyquist below 0.2 Hz
  SolveOptions o;
  o.rel_tolerance = -1.0;
  EXPECT_THAT([&] { (void)solve(pr, Method::Exact, default_bounds(1e-3), o); },
              testing::ThrowsMessage<core::InputError>(testing::HasSubstr("rel_tolerance")));
  const Bounds d = default_bounds(1e-3);
  EXPECT_DOUBLE_EQ(d.p_min, kTwoPi * 0.2);
  EXPECT_DOUBLE_EQ(d.wn_max, std::numbers::pi / 1e-3);
  EXPECT_STREQ(method_name(Method::Exact), "exact");
}

}  // namespace
}  // namespace servotwin::rapid
