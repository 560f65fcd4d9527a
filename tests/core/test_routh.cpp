// Routh–Hurwitz test (core::is_hurwitz). Expected answers come from closed forms (Hurwitz
// determinants of low degrees, polynomials built from known roots) and from brute force: the
// roots of random polynomials (Polynomial::roots, i.e. the companion-matrix eigenvalues).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "servotwin/core/polynomial.hpp"

namespace servotwin::core {
namespace {

using Complex = std::complex<double>;

Polynomial from_roots(const std::vector<Complex>& roots, double gain = 1.0) {
  return Polynomial::from_roots(roots, gain);
}

/// Roots of a damped mode and its mirror image in the imaginary axis.
std::vector<Complex> mode(double re, double im) { return {Complex(re, im), Complex(re, -im)}; }

TEST(Routh, ConstantsAndLowDegreeClosedForms) {
  EXPECT_TRUE(is_hurwitz(Polynomial{3.0}));
  EXPECT_TRUE(is_hurwitz(Polynomial{-0.5}));
  // Degree 1 and 2: Hurwitz iff all coefficients have the sign of the leading one.
  EXPECT_TRUE(is_hurwitz(Polynomial{2.0, 5.0}));
  EXPECT_FALSE(is_hurwitz(Polynomial{2.0, -5.0}));
  EXPECT_FALSE(is_hurwitz(Polynomial{2.0, 0.0}));  // root at 0
  EXPECT_TRUE(is_hurwitz(Polynomial{-1.0, -3.0, -2.0}));
  EXPECT_FALSE(is_hurwitz(Polynomial{1.0, 0.0, 4.0}));   // +-2j
  EXPECT_FALSE(is_hurwitz(Polynomial{1.0, -1e-9, 4.0}));
  EXPECT_FALSE(is_hurwitz(Polynomial{1.0, 3.0, -2.0}));
}

TEST(Routh, CubicHurwitzDeterminantBoundary) {
  // s^3 + a s^2 + b s + k with a, b > 0 is Hurwitz iff 0 < k < a b (second Hurwitz determinant);
  // at k = a b the roots are -a and +-j sqrt(b): a zero in the first column, reported as not
  // Hurwitz.
  for (const double a : {0.3, 2.0, 40.0}) {
    for (const double b : {0.01, 3.0, 900.0}) {
      const double limit = a * b;
      EXPECT_TRUE(is_hurwitz(Polynomial{1.0, a, b, limit * (1.0 - 1e-9)})) << a << " " << b;
      EXPECT_FALSE(is_hurwitz(Polynomial{1.0, a, b, limit * (1.0 + 1e-9)})) << a << " " << b;
      EXPECT_TRUE(is_hurwitz(Polynomial{1.0, a, b, 1e-6 * limit}));
      EXPECT_FALSE(is_hurwitz(Polynomial{1.0, a, b, -1e-6 * limit}));
    }
  }
  EXPECT_FALSE(is_hurwitz(Polynomial{1.0, 2.0, 3.0, 6.0}));  // (s + 2)(s^2 + 3): exact zero in the first column
}

TEST(Routh, LeadingSignIsNormalised) {
  const Polynomial stable = from_roots({-1.0, -2.0, Complex(-0.3, 4.0), Complex(-0.3, -4.0)});
  EXPECT_TRUE(is_hurwitz(stable));
  EXPECT_TRUE(is_hurwitz(-2.5 * stable));
  const Polynomial unstable = from_roots({-1.0, 2.0, Complex(-0.3, 4.0), Complex(-0.3, -4.0)});
  EXPECT_FALSE(is_hurwitz(unstable));
  EXPECT_FALSE(is_hurwitz(-2.5 * unstable));
}

TEST(Routh, DegenerateRowsAreNotHurwitz) {
  // All-zero rows: root pairs symmetric about the origin (on the imaginary axis or +-real).
  EXPECT_FALSE(is_hurwitz(from_roots({Complex(0, 1), Complex(0, -1), Complex(0, 2), Complex(0, -2)})));
  EXPECT_FALSE(is_hurwitz(from_roots({Complex(0, 1), Complex(0, -1), -1.0, -2.0})));
  EXPECT_FALSE(is_hurwitz(from_roots({1.0, -1.0, -2.0, -3.0})));
  EXPECT_FALSE(is_hurwitz(from_roots({Complex(1, 1), Complex(1, -1), Complex(-1, 1), Complex(-1, -1), -3.0})));
  // A root at the origin: zero constant coefficient.
  EXPECT_FALSE(is_hurwitz(from_roots({0.0, -1.0, -2.0, Complex(-1, 3), Complex(-1, -3)})));
  // Repeated stable roots are fine.
  EXPECT_TRUE(is_hurwitz(from_roots(std::vector<Complex>(12, Complex(-1.0, 0.0)))));
}

TEST(Routh, NearMarginalQuarticIsDecidedExactly) {
  // A lightly damped quartic like the Kharitonov vertex k3 of the issue-7 plan (E28): its
  // rightmost roots have Re = -6.0e-4, far above rounding but close enough that a root-based
  // tolerance would flip it. The mirror pair (+6.0e-4) must fail.
  const double margin = 6.0e-4;
  for (const double scale : {1e-3, 1.0, 1e3}) {  // units: rad/s, krad/s, mrad/s
    std::vector<Complex> roots = mode(-margin * scale, 1.7 * scale);
    const std::vector<Complex> rigid = mode(-0.9 * scale, 0.35 * scale);
    roots.insert(roots.end(), rigid.begin(), rigid.end());
    EXPECT_TRUE(is_hurwitz(from_roots(roots, 3.0))) << scale;
    roots[0] = Complex(margin * scale, 1.7 * scale);
    roots[1] = std::conj(roots[0]);
    EXPECT_FALSE(is_hurwitz(from_roots(roots, 3.0))) << scale;
  }
}

TEST(Routh, ButterworthUpToDegreeTwelve) {
  // Butterworth roots lie on the left half of the unit circle; the mirrored set is anti-Hurwitz.
  for (int n = 1; n <= 12; ++n) {
    std::vector<Complex> roots, mirrored;
    for (int k = 0; k < n; ++k) {
      const double theta = std::numbers::pi * (2.0 * k + n + 1) / (2.0 * n);
      roots.emplace_back(std::cos(theta), std::sin(theta));
      mirrored.emplace_back(-std::cos(theta), std::sin(theta));
    }
    EXPECT_TRUE(is_hurwitz(from_roots(roots))) << n;
    EXPECT_FALSE(is_hurwitz(from_roots(mirrored))) << n;
  }
}

TEST(Routh, ExtremeFrequencyScalesDoNotOverflow) {
  // s -> s / w scales the coefficients by w^k; the Hurwitz property is scale-invariant.
  for (const double w : {1e-45, 1e-20, 1.0, 1e20, 1e45}) {
    std::vector<Complex> roots = mode(-1e-3 * w, w);
    for (const double r : {-0.5, -2.0, -7.0}) roots.emplace_back(r * w, 0.0);
    EXPECT_TRUE(is_hurwitz(from_roots(roots))) << w;
    roots.back() = Complex(7.0 * w, 0.0);
    EXPECT_FALSE(is_hurwitz(from_roots(roots))) << w;
  }
}

TEST(Routh, CoefficientsSpanningTheExponentRange) {
  // a3 s^3 + a2 s^2 + a1 s + a0 is Hurwitz iff a2 a1 > a3 a0 (all positive). Here a3 / a2 = 1e350
  // is not representable: without rescaling the rows the Routh ratio overflows to infinity.
  EXPECT_TRUE(is_hurwitz(Polynomial{1e100, 1e-250, 1e200, 1e-160}));   // 1e-50 > 1e-60
  EXPECT_FALSE(is_hurwitz(Polynomial{1e100, 1e-250, 1e200, 1e-140}));  // 1e-50 < 1e-40
}

TEST(Routh, RandomPolynomialsFromKnownRoots) {
  // Roots drawn at random (seeded): moduli log-uniform over [0.1, 100], real parts of either sign
  // at least 2 % of the modulus away from the axis. The truth is the sign of the rightmost drawn
  // root, independent of any numerical root finder.
  std::mt19937_64 rng(20261123);
  std::uniform_real_distribution<double> log_modulus(-1.0, 2.0), angle_fraction(0.02, 1.0), unit(0.0, 1.0);
  int stable = 0, unstable = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const int degree = 1 + trial % 12;
    const bool want_stable = unit(rng) < 0.5;
    std::vector<Complex> roots;
    while (static_cast<int>(roots.size()) < degree) {
      const double modulus = std::pow(10.0, log_modulus(rng));
      // Unstable sets get exactly one random right-half-plane root or pair.
      const bool right = !want_stable && roots.empty();
      const double re_fraction = angle_fraction(rng) * (right ? 1.0 : -1.0);
      if (degree - static_cast<int>(roots.size()) >= 2 && unit(rng) < 0.6) {
        const double re = re_fraction * modulus;
        const double im = std::sqrt(modulus * modulus - re * re);
        roots.emplace_back(re, im);
        roots.emplace_back(re, -im);
      } else {
        roots.emplace_back(std::copysign(modulus, re_fraction), 0.0);
      }
    }
    std::shuffle(roots.begin(), roots.end(), rng);
    const double gain = (unit(rng) < 0.5 ? -1.0 : 1.0) * std::pow(10.0, 4.0 * unit(rng) - 2.0);
    // from_roots pairs conjugates itself; shuffle only moves them apart.
    const Polynomial p = from_roots(roots, gain);
    ASSERT_EQ(is_hurwitz(p), want_stable) << "trial " << trial << " degree " << degree;
    (want_stable ? stable : unstable)++;
  }
  EXPECT_GT(stable, 1500);
  EXPECT_GT(unstable, 1500);
}

TEST(Routh, RandomCoefficientsAgainstRootFinder) {
  // Positive random coefficients (so the trivial sign test never decides), degrees 3..12, checked
  // against the eigenvalue-based roots. Cases whose rightmost root lies within 1e-6 of the
  // largest root modulus from the axis are skipped as numerically ambiguous for either method.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> log_coefficient(-1.0, 1.0);
  int stable = 0, unstable = 0, ambiguous = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    const int degree = 3 + trial % 10;
    std::vector<double> c(static_cast<std::size_t>(degree) + 1);
    for (double& v : c) v = std::pow(10.0, log_coefficient(rng));
    const Polynomial p(c);
    const std::vector<Complex> roots = p.roots();
    double rightmost = -std::numeric_limits<double>::infinity(), largest = 0.0;
    for (const Complex& r : roots) {
      rightmost = std::max(rightmost, r.real());
      largest = std::max(largest, std::abs(r));
    }
    if (std::abs(rightmost) < 1e-6 * largest) {
      ++ambiguous;
      continue;
    }
    ASSERT_EQ(is_hurwitz(p), rightmost < 0.0) << "trial " << trial << " rightmost " << rightmost;
    (rightmost < 0.0 ? stable : unstable)++;
  }
  EXPECT_GT(stable, 300);  // low degrees are often stable, high degrees rarely
  EXPECT_GT(unstable, 3000);
  EXPECT_LT(ambiguous, 10);
}

TEST(Routh, RandomNearMarginalRootSets) {
  // Like RandomPolynomialsFromKnownRoots, but the decisive mode (the only one near the axis, on
  // either side) has a relative margin |Re| / |root| log-uniform over [1e-9, 1e-2], the others
  // at least 10 %; degrees 2..12, moduli over [0.1, 100].
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 3000; ++trial) {
    const int degree = 2 + trial % 11;
    const bool want_stable = trial % 2 == 0;
    const double margin = std::pow(10.0, -9.0 + 7.0 * unit(rng));
    const double modulus = std::pow(10.0, -1.0 + 3.0 * unit(rng));
    std::vector<Complex> roots = mode((want_stable ? -1.0 : 1.0) * margin * modulus, modulus * std::sqrt(1.0 - margin * margin));
    while (static_cast<int>(roots.size()) < degree) {
      const double m = std::pow(10.0, -1.0 + 3.0 * unit(rng));
      const double fraction = 0.1 + 0.9 * unit(rng);
      if (degree - static_cast<int>(roots.size()) >= 2) {
        const std::vector<Complex> pair = mode(-fraction * m, m * std::sqrt(1.0 - fraction * fraction));
        roots.insert(roots.end(), pair.begin(), pair.end());
      } else {
        roots.emplace_back(-m, 0.0);
      }
    }
    ASSERT_EQ(is_hurwitz(from_roots(roots)), want_stable) << "trial " << trial << " margin " << margin;
  }
}

TEST(Routh, RejectsInvalidPolynomials) {
  EXPECT_THROW((void)is_hurwitz(Polynomial()), std::invalid_argument);
  EXPECT_THROW((void)is_hurwitz(Polynomial{0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW((void)is_hurwitz(Polynomial{1.0, std::numeric_limits<double>::quiet_NaN(), 1.0}), std::invalid_argument);
  EXPECT_THROW((void)is_hurwitz(Polynomial{1.0, 2.0, std::numeric_limits<double>::infinity()}), std::invalid_argument);
}

}  // namespace
}  // namespace servotwin::core
