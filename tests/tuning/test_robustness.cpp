// Interval-parameter robustness of the PI velocity loop (catalog C7.9, E28).
// References: tests/data/tuning/tuning_reference.json "robustness", written by
// tools/reference/tuning_reference.py (closed loop expanded with numpy.polymul, stability from
// numpy.roots / batched companion eigenvalues, design by the c(s1) evaluation); the catalog's E28
// numbers; brute-force rooting (core::Polynomial::roots) of every grid case; a seeded Monte-Carlo.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/tuning/robustness.hpp"

namespace servotwin::tuning {
namespace {

using core::Polynomial;
using test::kSqrtHalf;
using test::reference;

using test::expect_input_error;

PlantParameters params_of(const nlohmann::json& j) {
  return {j.at("k"), j.at("a"), j.at("xi"), j.at("xi_z"), j.at("omega"), j.at("omega_z")};
}

/// A fixture parameter point [K, a, ξ, ξz, ω, ωz].
PlantParameters params_of_list(const nlohmann::json& j) {
  return {j.at(0), j.at(1), j.at(2), j.at(3), j.at(4), j.at(5)};
}

IntervalPlant box_of(const std::string& name) {
  const nlohmann::json& r = reference().at("robustness");
  return make_interval_plant(params_of(r.at("nominal")), params_of(r.at("spreads").at(name)));
}

const nlohmann::json& fixture_case(const std::string& box, double zeta_star) {
  for (const nlohmann::json& c : reference().at("robustness").at("cases"))
    if (c.at("box") == box && c.at("zeta_star").get<double>() == zeta_star) return c;
  throw std::runtime_error("no fixture case " + box);
}

void expect_same_point(const PlantParameters& got, const nlohmann::json& want) {
  const PlantParameters w = params_of_list(want);
  EXPECT_DOUBLE_EQ(got.k, w.k);
  EXPECT_DOUBLE_EQ(got.a, w.a);
  EXPECT_DOUBLE_EQ(got.xi, w.xi);
  EXPECT_DOUBLE_EQ(got.xi_z, w.xi_z);
  EXPECT_DOUBLE_EQ(got.omega, w.omega);
  EXPECT_DOUBLE_EQ(got.omega_z, w.omega_z);
}

double max_real_part(const Polynomial& p) {
  double m = -HUGE_VAL;
  for (const std::complex<double>& z : p.roots()) m = std::max(m, z.real());
  return m;
}

TEST(Robustness, ClosedLoopCoefficientsEqualTheExpandedLoop) {
  // Independent expansion: s·(s + a)(s² + 2ξωs + ω²) + (Kp s + Ki)·K(s² + 2ξzωz s + ωz²) with
  // core::Polynomial products, and the generic closed_loop_polynomial() of the transfer function.
  const std::vector<PlantParameters> points = {
      {1.0, 0.1, 0.02, 0.01, 2.0, 1.0}, {37.0, 2.5, 0.07, 0.03, 76.0, 28.3}, {0.02, 0.0, 0.0, 0.0, 5.0, 3.0}};
  const PiGains g{3.1, 1.7};
  for (const PlantParameters& p : points) {
    const Polynomial s{1.0, 0.0};
    const Polynomial den = Polynomial{1.0, p.a} * Polynomial{1.0, 2.0 * p.xi * p.omega, p.omega * p.omega};
    const Polynomial num = p.k * Polynomial{1.0, 2.0 * p.xi_z * p.omega_z, p.omega_z * p.omega_z};
    const Polynomial expanded = s * den + Polynomial{g.kp, g.ki} * num;
    const Polynomial generic = closed_loop_polynomial(plant_transfer_function(p), PidGains{g.kp, g.ki, 0.0, 0.0});
    const Polynomial c = closed_loop_polynomial(p, g);
    ASSERT_EQ(c.degree(), 4);
    ASSERT_EQ(expanded.degree(), 4);
    for (int k = 0; k <= 4; ++k) {
      const double scale = std::max(std::abs(expanded.coefficient_of_power(k)), 1e-300);
      EXPECT_LT(std::abs(c.coefficient_of_power(k) - expanded.coefficient_of_power(k)) / scale, 1e-14) << k;
      EXPECT_LT(std::abs(generic.coefficient_of_power(k) - expanded.coefficient_of_power(k)) / scale, 1e-14) << k;
    }
  }
}

TEST(Robustness, CoefficientBoundsEncloseEveryPlantOfTheBox) {
  // Monotonicity (header): random plants in the box never leave [lower, upper], and the bounds are
  // attained (the all-lower and all-upper plants).
  const IntervalPlant box = box_of("wide");
  const PiGains g{3.4, 1.2};
  const KharitonovResult kh = kharitonov(box, g);
  std::mt19937_64 rng(7);
  const auto draw = [&](const Interval& v) { return std::uniform_real_distribution<double>(v.lo, v.hi)(rng); };
  for (int i = 0; i < 2000; ++i) {
    const PlantParameters p{draw(box.k), draw(box.a), draw(box.xi), draw(box.xi_z), draw(box.omega), draw(box.omega_z)};
    const Polynomial c = closed_loop_polynomial(p, g);
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(c.coefficient_of_power(k), kh.lower[static_cast<std::size_t>(k)] * (1.0 - 1e-14));
      EXPECT_LE(c.coefficient_of_power(k), kh.upper[static_cast<std::size_t>(k)] * (1.0 + 1e-14));
    }
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_DOUBLE_EQ(closed_loop_polynomial(box.lower(), g).coefficient_of_power(k),
                     kh.lower[static_cast<std::size_t>(k)]);
    EXPECT_DOUBLE_EQ(closed_loop_polynomial(box.upper(), g).coefficient_of_power(k),
                     kh.upper[static_cast<std::size_t>(k)]);
  }
}

TEST(Robustness, E28KharitonovAllFourHurwitzWithNearlyMarginalK3) {
  // E28: K = 1, a = 0.1, ξ = 0.02, ξz = 0.01, ω = 2, ωz = 1; ±10 %, ω ±30 %, ω* = 0.9. The box that
  // reproduces the catalog's k3 margins holds ξz at its nominal value ("catalog" in the fixture;
  // see LiteralE28BoxFailsKharitonovButPassesTheGrid for ξz ±10 %).
  const IntervalPlant box = box_of("catalog");
  struct Printed {
    double zeta_star, kp, ki, k3_max_re, k3_tol;
  };
  // Catalog E28 [D]: gains to 6 decimals, k3's rightmost root −6.0e-4 and −0.022 (2 digits).
  for (const Printed& e :
       {Printed{kSqrtHalf, 3.429190, 1.248403, -6.0e-4, 0.05e-4}, Printed{1.0, 3.294913, 1.061761, -0.022, 0.5e-3}}) {
    const nlohmann::json& f = fixture_case("catalog", e.zeta_star);
    const PiGains g = nominal_pi_design(box, 0.9, e.zeta_star);
    EXPECT_NEAR(g.kp, e.kp, 1e-6);
    EXPECT_NEAR(g.ki, e.ki, 1e-6);
    EXPECT_LT(test::rel_diff(g.kp, f.at("kp").get<double>()), 1e-12);
    EXPECT_LT(test::rel_diff(g.ki, f.at("ki").get<double>()), 1e-12);
    const KharitonovResult kh = kharitonov(box, g);
    const nlohmann::json& fk = f.at("kharitonov");
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_LT(test::rel_diff(kh.lower[k], fk.at("lower").at(k).get<double>()), 1e-13);
      EXPECT_LT(test::rel_diff(kh.upper[k], fk.at("upper").at(k).get<double>()), 1e-13);
    }
    for (std::size_t i = 0; i < 4; ++i) {
      for (int c = 0; c < 5; ++c)
        EXPECT_LT(test::rel_diff(kh.polynomials[i].coefficients()[static_cast<std::size_t>(c)],
                                 fk.at("polynomials").at(i).at(c).get<double>()),
                  1e-13);
      EXPECT_TRUE(kh.hurwitz[i]) << "k" << i + 1;
      EXPECT_NEAR(kh.max_real_part[i], fk.at("max_real_part").at(i).get<double>(), 1e-10) << "k" << i + 1;
    }
    EXPECT_TRUE(kh.robust);
    EXPECT_NEAR(kh.max_real_part[2], e.k3_max_re, e.k3_tol);
    EXPECT_GT(kh.max_real_part[2], -0.03);  // k3 is the nearly marginal one
  }
}

TEST(Robustness, E28GridMatchesTheFixture) {
  for (const std::string name : {"catalog", "literal", "wide"}) {
    const IntervalPlant box = box_of(name);
    for (double zs : {kSqrtHalf, 1.0}) {
      const nlohmann::json& f = fixture_case(name, zs);
      const PiGains g{f.at("kp").get<double>(), f.at("ki").get<double>()};
      const GridResult grid = grid_check(box, g);
      const nlohmann::json& fg = f.at("grid");
      EXPECT_EQ(grid.cases, fg.at("cases").get<std::size_t>()) << name;
      EXPECT_EQ(grid.failures, fg.at("failures").get<std::size_t>()) << name;
      EXPECT_EQ(grid.robust, grid.failures == 0);
      EXPECT_NEAR(grid.worst_max_real_part, fg.at("worst_max_real_part").get<double>(), 1e-10) << name;
      expect_same_point(grid.worst, fg.at("worst"));
      EXPECT_EQ(grid.first_failure.has_value(), !fg.at("first_failure").is_null());
      if (grid.first_failure) expect_same_point(*grid.first_failure, fg.at("first_failure"));
    }
  }
}

TEST(Robustness, LiteralE28BoxFailsKharitonovButPassesTheGrid) {
  // ξz ±10 % too: k3 of the ξ* = √2/2 design gets a root at +6.4e-5 (fixture, numpy.roots), so the
  // (conservative) Kharitonov test fails while every one of the 5⁶ grid plants is stable.
  const IntervalPlant box = box_of("literal");
  const nlohmann::json& f = fixture_case("literal", kSqrtHalf);
  const PiGains g = nominal_pi_design(box, 0.9, kSqrtHalf);
  const KharitonovResult kh = kharitonov(box, g);
  EXPECT_FALSE(kh.robust);
  EXPECT_TRUE(kh.hurwitz[0] && kh.hurwitz[1] && kh.hurwitz[3]);
  EXPECT_FALSE(kh.hurwitz[2]);
  EXPECT_NEAR(kh.max_real_part[2], f.at("kharitonov").at("max_real_part").at(2).get<double>(), 1e-10);
  EXPECT_GT(kh.max_real_part[2], 0.0);
  const GridResult grid = grid_check(box, g);
  EXPECT_TRUE(grid.robust);
  EXPECT_EQ(grid.cases, 15625u);
  EXPECT_TRUE(robustly_stable(box, g));
  // ξ* = 1 stays Kharitonov-robust on this box (fixture).
  EXPECT_TRUE(kharitonov(box, nominal_pi_design(box, 0.9, 1.0)).robust);
  EXPECT_TRUE(fixture_case("literal", 1.0).at("kharitonov").at("robust").get<bool>());
}

TEST(Robustness, WideBoxGridAgreesWithBruteForceRoots) {
  // ±50 % on everything: non-collocated corners (ω < ωz) make both tests fail. Every grid case is
  // re-enumerated here and rooted (core::Polynomial::roots), and also given to core::is_hurwitz.
  const IntervalPlant box = box_of("wide");
  const PiGains g = nominal_pi_design(box, 0.9, kSqrtHalf);
  EXPECT_FALSE(kharitonov(box, g).robust);
  const GridResult grid = grid_check(box, g);
  EXPECT_FALSE(grid.robust);
  EXPECT_FALSE(robustly_stable(box, g));
  const auto values = [](const Interval& v) {
    std::vector<double> out;
    for (int i = 0; i < 5; ++i) out.push_back(i == 4 ? v.hi : v.lo + (v.hi - v.lo) * 0.25 * i);
    return out;
  };
  std::size_t cases = 0, unstable_by_roots = 0, unstable_by_routh = 0;
  double worst = -HUGE_VAL;
  for (double k : values(box.k))
    for (double a : values(box.a))
      for (double xi : values(box.xi))
        for (double xz : values(box.xi_z))
          for (double w : values(box.omega))
            for (double wz : values(box.omega_z)) {
              const Polynomial c = closed_loop_polynomial(PlantParameters{k, a, xi, xz, w, wz}, g);
              const double m = max_real_part(c);
              ++cases;
              worst = std::max(worst, m);
              if (m >= 0.0) ++unstable_by_roots;
              if (!core::is_hurwitz(c)) ++unstable_by_routh;
            }
  EXPECT_EQ(grid.cases, cases);
  EXPECT_EQ(grid.failures, unstable_by_roots);
  EXPECT_EQ(grid.failures, unstable_by_routh);
  EXPECT_GT(grid.failures, 0u);
  EXPECT_DOUBLE_EQ(grid.worst_max_real_part, worst);
  EXPECT_GT(grid.worst_max_real_part, 0.0);
  ASSERT_TRUE(grid.first_failure.has_value());
  EXPECT_GE(max_real_part(closed_loop_polynomial(*grid.first_failure, g)), 0.0);
}

TEST(Robustness, MonteCarloFindsNoUnstablePlantWhenKharitonovSaysRobust) {
  // 10⁴ seeded uniform plants in the E28 box for each Kharitonov-robust design: all stable by both
  // the Routh test and the roots. The same sampler on the wide box does find unstable plants.
  for (double zs : {kSqrtHalf, 1.0}) {
    const IntervalPlant box = box_of("catalog");
    const PiGains g = nominal_pi_design(box, 0.9, zs);
    ASSERT_TRUE(kharitonov(box, g).robust);
    std::mt19937_64 rng(20261123);
    const auto draw = [&](const Interval& v) { return std::uniform_real_distribution<double>(v.lo, v.hi)(rng); };
    int unstable = 0;
    double worst = -HUGE_VAL;
    for (int i = 0; i < 10000; ++i) {
      const Polynomial c = closed_loop_polynomial(
          PlantParameters{draw(box.k), draw(box.a), draw(box.xi), draw(box.xi_z), draw(box.omega), draw(box.omega_z)},
          g);
      const double m = max_real_part(c);
      worst = std::max(worst, m);
      if (!core::is_hurwitz(c) || m >= 0.0) ++unstable;
    }
    EXPECT_EQ(unstable, 0) << zs;
    // The grid's worst case bounds the sampled abscissa from above here (it sits at a vertex).
    EXPECT_LE(worst, grid_check(box, g).worst_max_real_part + 1e-12);
  }
  const IntervalPlant wide = box_of("wide");
  const PiGains g = nominal_pi_design(wide, 0.9, kSqrtHalf);
  std::mt19937_64 rng(1);
  const auto draw = [&](const Interval& v) { return std::uniform_real_distribution<double>(v.lo, v.hi)(rng); };
  int unstable = 0;
  for (int i = 0; i < 2000; ++i)
    if (!core::is_hurwitz(closed_loop_polynomial(PlantParameters{draw(wide.k), draw(wide.a), draw(wide.xi),
                                                                 draw(wide.xi_z), draw(wide.omega), draw(wide.omega_z)},
                                                 g)))
      ++unstable;
  EXPECT_GT(unstable, 0);
}

TEST(Robustness, RobustlyStableIsKharitonovOrGrid) {
  // robustly_stable() has its own allocation-free early-exit path: same verdict as the two
  // diagnostic functions over a sweep of designs on every box (both outcomes occur).
  int passes = 0, fails = 0;
  for (const std::string name : {"catalog", "literal", "wide"})
    for (double zs : {kSqrtHalf, 1.0})
      for (double w = 0.1; w < 1.0; w += 0.1) {
        const IntervalPlant box = box_of(name);
        const PiGains g = nominal_pi_design(box, w, zs);
        if (g.kp < 0.0 || g.ki < 0.0) continue;
        const bool want = kharitonov(box, g).robust || grid_check(box, g).robust;
        EXPECT_EQ(robustly_stable(box, g), want) << name << " " << w;
        (want ? passes : fails) += 1;
      }
  EXPECT_GT(passes, 0);
  EXPECT_GT(fails, 0);
}

TEST(Robustness, VerdictsDoNotDependOnTheTimeUnit) {
  // P_c(s) = P(s/c) for frequencies and K times c; the PI C(s/c) has Kp' = Kp, Ki' = c·Ki.
  const double c = 2.0 * std::numbers::pi;
  for (const std::string name : {"catalog", "literal", "wide"}) {
    const IntervalPlant box = box_of(name);
    IntervalPlant scaled = box;
    for (Interval* v : {&scaled.k, &scaled.a, &scaled.omega, &scaled.omega_z})
      *v = {v->lo * c, v->nominal * c, v->hi * c};
    const PiGains g = nominal_pi_design(box, 0.9, kSqrtHalf);
    const PiGains gs = nominal_pi_design(scaled, 0.9 * c, kSqrtHalf);
    EXPECT_LT(test::rel_diff(gs.kp, g.kp), 1e-12);
    EXPECT_LT(test::rel_diff(gs.ki, c * g.ki), 1e-12);
    const KharitonovResult a = kharitonov(box, g), b = kharitonov(scaled, gs);
    EXPECT_EQ(a.hurwitz, b.hurwitz) << name;
    const GridResult ga = grid_check(box, g), gb = grid_check(scaled, gs);
    EXPECT_EQ(ga.failures, gb.failures) << name;
    EXPECT_NEAR(gb.worst_max_real_part, c * ga.worst_max_real_part, 1e-9);
  }
}

TEST(Robustness, LargestRobustOmegaStarMatchesTheReferenceSearch) {
  // Fixture: the same method (header) in numpy with its own admissible range and root-based tests.
  for (const nlohmann::json& f : reference().at("robustness").at("largest")) {
    const PlantParameters nominal = params_of(f.at("nominal"));
    const IntervalPlant box = make_interval_plant(nominal, params_of(f.at("spread")));
    const double zs = f.at("zeta_star");
    const double want = f.at("omega_star");
    const double got = largest_robust_omega_star(box, zs);
    const std::string label = f.at("box").get<std::string>() + " zeta* " + std::to_string(zs);
    EXPECT_NEAR(got, want, 2e-5 * nominal.omega_z) << label;
    if (got > 0.0) {
      EXPECT_TRUE(robustly_stable(box, nominal_pi_design(box, got, zs))) << label;
      const double omega_max = admissible_range(nominal_normalized_plant(box), zs).omega_max * nominal.omega_z;
      if (got < omega_max * (1.0 - 1e-9)) {  // the bisection stopped at a genuine boundary
        EXPECT_FALSE(robustly_stable(box, nominal_pi_design(box, got + 2e-5 * omega_max, zs))) << label;
      }
    }
  }
}

TEST(Robustness, BadInputsNameTheField) {
  const PlantParameters nominal{1.0, 0.1, 0.02, 0.01, 2.0, 1.0};
  const PlantParameters spread{0.1, 0.1, 0.1, 0.1, 0.3, 0.1};
  const IntervalPlant good = make_interval_plant(nominal, spread);
  expect_input_error(
      [&] {
        (void)make_interval_plant(nominal, {0.1, 0.1, 1.5, 0.1, 0.3, 0.1});
      },
      "spread.xi", "relative spread in [0, 1]");
  expect_input_error(
      [&] {
        (void)make_interval_plant(nominal, {1.0, 0.1, 0.1, 0.1, 0.3, 0.1});
      },
      "k.lo", "expected a lower bound > 0, got 0");
  expect_input_error([&] { (void)make_interval_plant({1.0, -0.1, 0.02, 0.01, 2.0, 1.0}, spread); }, "a.lo", ">= 0");
  IntervalPlant p = good;
  p.omega.nominal = 3.0;
  expect_input_error([&] { validate(p); }, "omega.hi", "expected nominal <= hi");
  p = good;
  p.xi_z.lo = 0.02;
  expect_input_error([&] { validate(p); }, "xi_z.nominal", "expected lo <= nominal");
  p = good;
  p.omega_z.hi = std::nan("");
  expect_input_error([&] { (void)kharitonov(p, {1.0, 1.0}); }, "omega_z.hi", "finite");
  p = good;
  p.omega_z.lo = 0.0;
  expect_input_error([&] { (void)grid_check(p, {1.0, 1.0}); }, "omega_z.lo", "> 0");
  expect_input_error([&] { (void)kharitonov(good, {-1.0, 1.0}); }, "gains.kp", "expected a proportional gain Kp >= 0");
  expect_input_error([&] { (void)grid_check(good, {1.0, -0.5}); }, "gains.ki", "expected an integral gain Ki >= 0");
  expect_input_error([&] { (void)grid_check(good, {1.0, 1.0}, 1); }, "points_per_parameter", "2 to 12");
  expect_input_error([&] { (void)grid_check(good, {1.0, 1.0}, 13); }, "points_per_parameter", "got 13");
  expect_input_error([&] { (void)largest_robust_omega_star(good, 0.0); }, "zeta_star", "damping ratio > 0");
  expect_input_error([&] { (void)nominal_pi_design(good, -1.0, 0.7); }, "omega_star", "bandwidth > 0");
  const IntervalPlant non_collocated = make_interval_plant({1.0, 0.1, 0.02, 0.01, 1.03, 1.0}, spread);
  expect_input_error([&] { (void)largest_robust_omega_star(non_collocated, 0.7); }, "r", "r > 1.05");
  // Degenerate intervals are fine: one grid value each.
  EXPECT_EQ(grid_check(make_interval_plant(nominal, {}), {1.0, 0.5}).cases, 1u);
}

}  // namespace
}  // namespace servotwin::tuning
