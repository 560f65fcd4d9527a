// The map (p, wn, zeta) <-> theta1 (Eq. 3.14), its inverse, its derivatives, and the thesis's
// printed tables (4.1, 4.2, 4.5): their model coefficients a1..a3 must give back the printed search
// variables to the printed precision.

#include <gtest/gtest.h>

#include <complex>
#include <random>

#include "rapid/test_solver_support.hpp"
#include "servotwin/core/polynomial.hpp"
#include "servotwin/rapid/solver.hpp"
#include "servotwin/rapid/solver_detail.hpp"

namespace servotwin::rapid {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace solver_poles_test {

constexpr double kTwoPi = test::kTwoPi;

Eigen::Vector3d theta1_from_coefficients(double a1, double a2, double a3) { return {a3 / a2, a1 / a2, 1.0 / a2}; }

TEST(SolverPoles, Theta1IsTheNormalizedCharacteristicPolynomial) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> lp(0.0, 8.0), z(0.05, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double p = std::exp(lp(rng)), wn = std::exp(lp(rng)), zeta = z(rng);
    const core::Polynomial poly = core::Polynomial{1.0, p} * core::Polynomial{1.0, 2.0 * zeta * wn, wn * wn};
    const auto c = poly.coefficients();
    const Eigen::Vector3d expected = theta1_from_coefficients(c[1], c[2], c[3]);
    const Eigen::Vector3d got = theta1_from_poles(p, wn, zeta);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got(k), expected(k), 1e-13 * std::abs(expected(k)));
  }
}

TEST(SolverPoles, FactorizationsInvertTheMap) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> lp(0.0, 8.0), z(0.05, 3.0);
  for (int trial = 0; trial < 300; ++trial) {
    const double p = std::exp(lp(rng)), wn = std::exp(lp(rng)), zeta = z(rng);
    const Eigen::Vector3d t = theta1_from_poles(p, wn, zeta);
    const std::vector<PoleFactorization> f = pole_factorizations(t);
    if (zeta < 0.999) {
      ASSERT_EQ(f.size(), 1u);
    } else if (zeta > 1.001) {
      ASSERT_EQ(f.size(), 3u);  // three real roots: each can be "p"
    }
    bool found = false;
    for (const auto& g : f) {
      const Eigen::Vector3d back = theta1_from_poles(g.p, g.wn, g.zeta);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(back(k), t(k), 1e-8 * std::abs(t(k)));
      found = found || (std::abs(g.p - p) < 1e-6 * p && std::abs(g.wn - wn) < 1e-6 * wn &&
                        std::abs(g.zeta - zeta) < 1e-6 * zeta);
    }
    EXPECT_TRUE(found) << p << " " << wn << " " << zeta;
  }
  // Unstable or degenerate polynomials.
  EXPECT_TRUE(pole_factorizations({1.0, 1.0, 0.0}).empty());
  const auto unstable = pole_factorizations(theta1_from_poles(-5.0, 10.0, 0.3));
  ASSERT_EQ(unstable.size(), 1u);
  EXPECT_NEAR(unstable[0].p, -5.0, 1e-9);
}

TEST(SolverPoles, ThesisTablesAreConsistent) {
  // {a1, a2, a3} and the printed {wn [Hz], zeta, p [Hz]} (Tables 4.1, 4.2, 4.5).
  struct Row {
    const char* name;
    double a1, a2, a3, wn_hz, zeta, p_hz;
  };
  const Row rows[] = {
      {"4.1 actual", 192.65, 44356.23, 316830.21, 33.0, 0.45, 1.17},
      {"4.1 LM", 214.13, 60040.19, 685295.65, 38.21, 0.42, 1.89},
      {"4.1 GA", 214.41, 60072.73, 703594.29, 38.20, 0.42, 1.94},
      {"4.2 LM", 225.94, 244579.87, 6551189.40, 77.83, 0.203, 4.36},
      {"4.2 GA", 223.76, 241310.90, 6510957.51, 77.30, 0.202, 4.39},
      {"4.5 X", 2948.25, 526359.32, 18813165.66, 13.14, 1.14, 439.27},
      {"4.5 Y", 4030.00, 699755.18, 26243010.58, 13.14, 1.09, 612.75},
  };
  for (const Row& r : rows) {
    const auto f = pole_factorizations(theta1_from_coefficients(r.a1, r.a2, r.a3));
    bool found = false;
    for (const auto& g : f) {
      // Printed to 3-4 digits; the 4.1 "actual" column is rounded to 2.
      const double rel = std::string(r.name) == "4.1 actual" ? 0.04 : 0.012;
      found = found || (std::abs(g.wn / kTwoPi - r.wn_hz) < rel * r.wn_hz &&
                        std::abs(g.p / kTwoPi - r.p_hz) < rel * r.p_hz && std::abs(g.zeta - r.zeta) < 0.011);
    }
    EXPECT_TRUE(found) << r.name;
  }
}

TEST(SolverPoles, LogJacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> lp(0.0, 8.0), z(0.05, 3.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Vector3d x(lp(rng), lp(rng), z(rng));
    const Eigen::Matrix3d j = detail::theta1_log_jacobian(std::exp(x(0)), std::exp(x(1)), x(2));
    for (int c = 0; c < 3; ++c) {
      const double h = 1e-6;
      Eigen::Vector3d xp = x, xm = x;
      xp(c) += h;
      xm(c) -= h;
      const Eigen::Vector3d d = (theta1_from_poles(std::exp(xp(0)), std::exp(xp(1)), xp(2)) -
                                 theta1_from_poles(std::exp(xm(0)), std::exp(xm(1)), xm(2))) /
                                (2.0 * h);
      const Eigen::Vector3d t = theta1_from_poles(std::exp(x(0)), std::exp(x(1)), x(2));
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(j(k, c), d(k), 1e-6 * std::abs(t(k)) + 1e-8 * std::abs(d(k)));
    }
  }
}

}  // namespace solver_poles_test
}  // namespace
}  // namespace servotwin::rapid
