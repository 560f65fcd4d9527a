#include "servotwin/core/polynomial.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/reference_data.hpp"

namespace servotwin::core {
namespace {

using Complex = std::complex<double>;
using test::reference_section;
using test::to_complex;

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// Worst relative error of `computed` against `reference` after pairing each reference root
/// with the nearest unused computed root (|error| / |reference|, absolute for a zero reference).
double worst_relative_error(std::vector<Complex> computed, const std::vector<Complex>& reference) {
  if (computed.size() != reference.size()) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (const Complex& r : reference) {
    auto nearest = std::min_element(computed.begin(), computed.end(),
                                    [&](Complex a, Complex b) { return std::abs(a - r) < std::abs(b - r); });
    const double scale = std::abs(r) > 0.0 ? std::abs(r) : 1.0;
    worst = std::max(worst, std::abs(*nearest - r) / scale);
    computed.erase(nearest);
  }
  return worst;
}

bool has_multiple_root(const std::vector<Complex>& roots) {
  for (std::size_t i = 0; i < roots.size(); ++i)
    for (std::size_t j = i + 1; j < roots.size(); ++j)
      if (roots[i] == roots[j]) return true;
  return false;
}

// ---- construction, evaluation, arithmetic ----------------------------------------------------

TEST(Polynomial, StripsLeadingZerosAndReportsDegree) {
  const Polynomial p{0.0, 0.0, 2.0, -3.0, 1.0};
  EXPECT_EQ(p.degree(), 2);
  EXPECT_EQ(std::vector<double>(p.coefficients().begin(), p.coefficients().end()), (std::vector<double>{2.0, -3.0, 1.0}));
  EXPECT_EQ(p.leading(), 2.0);
  EXPECT_EQ(p.coefficient_of_power(0), 1.0);
  EXPECT_EQ(p.coefficient_of_power(2), 2.0);
  EXPECT_EQ(p.coefficient_of_power(3), 0.0);
  EXPECT_EQ(p.coefficient_of_power(-1), 0.0);

  EXPECT_EQ(Polynomial().degree(), -1);
  EXPECT_TRUE(Polynomial({0.0, 0.0}).is_zero());
  EXPECT_EQ(Polynomial({5.0}).degree(), 0);
  EXPECT_EQ(Polynomial().leading(), 0.0);
}

TEST(Polynomial, EvaluatesLikeTheExpandedFormula) {
  const Polynomial p{2.0, -3.0, 0.5, 7.0};  // 2x^3 - 3x^2 + 0.5x + 7
  for (double x : {-2.0, -0.3, 0.0, 1.0, 4.5}) EXPECT_DOUBLE_EQ(p(x), 2 * x * x * x - 3 * x * x + 0.5 * x + 7);
  const Complex z(0.4, -1.3);
  const Complex expected = 2.0 * z * z * z - 3.0 * z * z + 0.5 * z + 7.0;
  EXPECT_NEAR(std::abs(p(z) - expected), 0.0, 1e-14 * std::abs(expected));
  EXPECT_EQ(Polynomial()(3.0), 0.0);
}

TEST(Polynomial, DerivativeOfPowerTerms) {
  EXPECT_EQ(Polynomial({2.0, -3.0, 0.5, 7.0}).derivative(), Polynomial({6.0, -6.0, 0.5}));
  EXPECT_TRUE(Polynomial({4.0}).derivative().is_zero());
  EXPECT_TRUE(Polynomial().derivative().is_zero());
}

TEST(Polynomial, Arithmetic) {
  const Polynomial a{1.0, 2.0};       // x + 2
  const Polynomial b{1.0, -1.0, 3.0};  // x^2 - x + 3
  EXPECT_EQ(a + b, Polynomial({1.0, 0.0, 5.0}));
  EXPECT_EQ(b - a, Polynomial({1.0, -2.0, 1.0}));
  EXPECT_EQ(a * b, Polynomial({1.0, 1.0, 1.0, 6.0}));
  EXPECT_EQ(2.0 * a, Polynomial({2.0, 4.0}));
  EXPECT_TRUE((a - a).is_zero());  // cancellation of the leading term gives the zero polynomial
  EXPECT_EQ((b - Polynomial({1.0, 0.0, 0.0})).degree(), 1);
  EXPECT_TRUE((a * Polynomial()).is_zero());
  EXPECT_TRUE((0.0 * a).is_zero());
}

TEST(Polynomial, FromRootsExpandsFactors) {
  const std::vector<Complex> real_roots{-1.0, -2.0};
  EXPECT_EQ(Polynomial::from_roots(real_roots), Polynomial({1.0, 3.0, 2.0}));
  const std::vector<Complex> pair{{-1.0, 2.0}, {-1.0, -2.0}};
  EXPECT_EQ(Polynomial::from_roots(pair, 3.0), Polynomial({3.0, 6.0, 15.0}));
  // Order of the conjugates does not matter, and a pair mixed with real roots works.
  const std::vector<Complex> mixed{{-1.0, -2.0}, 4.0, {-1.0, 2.0}};
  EXPECT_EQ(Polynomial::from_roots(mixed), Polynomial({1.0, -2.0, -3.0, -20.0}));
  EXPECT_EQ(Polynomial::from_roots(std::vector<Complex>{}, 2.5), Polynomial({2.5}));
}

TEST(Polynomial, FromRootsRejectsAComplexRootWithoutItsConjugate) {
  const std::vector<Complex> lonely{{-1.0, 2.0}, {-1.0, 2.0}};
  EXPECT_THROW((void)Polynomial::from_roots(lonely), std::invalid_argument);
  const std::vector<Complex> infinite{{std::numeric_limits<double>::infinity(), 0.0}};
  EXPECT_THROW((void)Polynomial::from_roots(infinite), std::invalid_argument);
}

// ---- roots -----------------------------------------------------------------------------------

TEST(PolynomialRoots, DegreeBelowOneHasNoRoots) {
  EXPECT_TRUE(Polynomial().roots().empty());
  EXPECT_TRUE(Polynomial({3.0}).roots().empty());
}

TEST(PolynomialRoots, LinearAndTrailingZerosAreExact) {
  const auto linear = Polynomial({4.0, -2.0}).roots();
  ASSERT_EQ(linear.size(), 1U);
  EXPECT_EQ(linear[0], Complex(0.5, 0.0));

  // s^3 (s + 1): three exact zeros (compared with ==, not a tolerance).
  const auto r = Polynomial({1.0, 1.0, 0.0, 0.0, 0.0}).roots();
  ASSERT_EQ(r.size(), 4U);
  EXPECT_EQ(std::count(r.begin(), r.end(), Complex(0.0, 0.0)), 3);
  EXPECT_EQ(std::count(r.begin(), r.end(), Complex(-1.0, 0.0)), 1);
  EXPECT_EQ(Polynomial({2.0, 0.0, 0.0}).roots(), (std::vector<Complex>{0.0, 0.0}));
}

TEST(PolynomialRoots, RejectsNonFiniteCoefficients) {
  EXPECT_THROW((void)Polynomial({1.0, std::nan(""), 2.0}).roots(), std::invalid_argument);
  EXPECT_THROW((void)Polynomial({1.0, 2.0, std::numeric_limits<double>::infinity()}).roots(), std::invalid_argument);
}

// Fixture cases (tools/reference/core_reference.py, "polynomial_roots"): the reference roots are
// exact (built from known roots) or 60-digit Newton refinements, i.e. the true roots of the double
// polynomial. Tolerance: no worse than twice numpy.roots' error on the same polynomial (numpy uses
// the same balanced-companion method without polishing, so this is what the method achieves),
// with a floor of 8 eps for roots numpy happens to get exactly. Polynomials with multiple roots
// must do far better than numpy (whose error there is eps^(1/m) ~ 1e-5): their clusters are
// recognised and collapsed, so the test demands 1e-13.
TEST(PolynomialRoots, MatchReferenceRootsAtLeastAsWellAsNumpy) {
  for (const auto& c : reference_section("polynomial_roots")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const Polynomial p(c.at("coefficients").get<std::vector<double>>());
    const std::vector<Complex> reference = to_complex(c.at("reference_roots"));
    const std::vector<Complex> computed = p.roots();
    ASSERT_EQ(computed.size(), static_cast<std::size_t>(p.degree()));
    const double ours = worst_relative_error(computed, reference);
    const double numpy = worst_relative_error(to_complex(c.at("numpy_roots")), reference);
    EXPECT_LE(ours, std::max(2.0 * numpy, 8.0 * kEps)) << "numpy error " << numpy;
    if (has_multiple_root(reference)) {
      EXPECT_LE(ours, 1e-13) << "numpy error " << numpy;
    }
  }
}

TEST(PolynomialRoots, ComplexRootsComeInExactConjugatePairsAndRealRootsAreReal) {
  for (const auto& c : reference_section("polynomial_roots")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    const std::vector<Complex> roots = Polynomial(c.at("coefficients").get<std::vector<double>>()).roots();
    const std::vector<Complex> reference = to_complex(c.at("reference_roots"));
    const auto reference_real = std::count_if(reference.begin(), reference.end(), [](Complex z) { return z.imag() == 0.0; });
    EXPECT_EQ(std::count_if(roots.begin(), roots.end(), [](Complex z) { return z.imag() == 0.0; }), reference_real);
    for (const Complex& z : roots)
      EXPECT_EQ(std::count(roots.begin(), roots.end(), z), std::count(roots.begin(), roots.end(), std::conj(z)));
  }
}

TEST(PolynomialRoots, ButterworthPolesMatchTheClosedForm) {
  // 8th-order analog Butterworth with cutoff 100 rad/s: poles 100 exp(j pi (2k + 9) / 16).
  const auto& c = test::reference_case("polynomial_roots", "butterworth_8");
  const std::vector<Complex> roots = Polynomial(c.at("coefficients").get<std::vector<double>>()).roots();
  // The coefficients themselves carry scipy's rounding (~1e-16 relative) amplified by the
  // conditioning of this polynomial (~1e3), hence 1e-12.
  EXPECT_LE(worst_relative_error(roots, to_complex(c.at("closed_form_roots"))), 1e-12);
}

TEST(PolynomialRoots, ProductsOfKnownFactorsGiveBackTheirRoots) {
  // Closed form: polynomials built as products of (s - r) with integer or dyadic roots have exactly
  // representable coefficients, so their exact roots are known.
  struct Case {
    std::vector<Complex> roots;
    double tolerance;  // relative; simple roots ~ eps * condition, multiple roots by clustering
  };
  const std::vector<Case> cases{
      {{-1.0, -1.0, -1.0, -2.0}, 1e-13},                          // triple root
      {{-0.5, -0.5, {-1.0, 2.0}, {-1.0, -2.0}, {-1.0, 2.0}, {-1.0, -2.0}}, 1e-13},  // double real, double pair
      {{-3.0, -3.0, -3.0, -3.0, -3.0}, 1e-13},                    // 5-fold
      {{2.0, -2.0, {0.0, 2.0}, {0.0, -2.0}}, 1e-14},             // s^4 - 16: equal moduli
      {{-0.125, -8.0, -64.0, -512.0}, 1e-14},                      // wide scale, dyadic
      {{0.0, 0.0, -1.0, -1.0, {-0.25, 4.0}, {-0.25, -4.0}}, 1e-13},
  };
  for (const Case& k : cases) {
    const Polynomial p = Polynomial::from_roots(k.roots);
    EXPECT_LE(worst_relative_error(p.roots(), k.roots), k.tolerance) << "degree " << p.degree();
  }
}

TEST(PolynomialRoots, RandomConjugateSetsAreRecovered) {
  // Roots drawn with a fixed seed; the polynomial from their product has rounded coefficients, so
  // the check is the backward one: every computed root makes |p| as small as the rounding of the
  // evaluation allows, and it is close to the generating root (random roots are well separated).
  std::mt19937 generator(12345);
  std::normal_distribution<double> normal(0.0, 3.0);
  for (int degree : {6, 10, 16}) {
    std::vector<Complex> roots;
    while (static_cast<int>(roots.size()) + 2 <= degree) {
      const Complex z(normal(generator), normal(generator));
      roots.push_back(z);
      roots.push_back(std::conj(z));
    }
    const Polynomial p = Polynomial::from_roots(roots);
    EXPECT_LE(worst_relative_error(p.roots(), roots), 1e-9) << "degree " << degree;
  }
}

TEST(PolynomialRoots, RandomCoefficientsOverManyDecadesGiveSmallRelativeResiduals) {
  // Property test (no reference needed): for every root the relative residual
  // |p(r)| / sum |c_k| |r|^k -- the smallest relative change of the coefficients that makes r an
  // exact root -- is at rounding level, the polynomial keeps its degree-many roots, and the set is
  // closed under conjugation. Coefficients span 1e-6 .. 1e6 with random signs and some zeros.
  std::mt19937 generator(2024);
  std::uniform_real_distribution<double> exponent(-6.0, 6.0);
  std::uniform_int_distribution<int> degree_of(1, 12);
  std::bernoulli_distribution negative(0.5);
  std::bernoulli_distribution zero(0.15);
  double worst = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const int degree = degree_of(generator);
    std::vector<double> c(static_cast<std::size_t>(degree + 1));
    for (double& v : c) v = zero(generator) ? 0.0 : (negative(generator) ? -1.0 : 1.0) * std::pow(10.0, exponent(generator));
    c.front() = std::pow(10.0, exponent(generator));
    const Polynomial p(c);
    const std::vector<Complex> roots = p.roots();
    ASSERT_EQ(roots.size(), static_cast<std::size_t>(degree)) << "trial " << trial;
    for (const Complex& r : roots) {
      ASSERT_TRUE(std::isfinite(r.real()) && std::isfinite(r.imag())) << "trial " << trial;
      EXPECT_EQ(std::count(roots.begin(), roots.end(), r), std::count(roots.begin(), roots.end(), std::conj(r)));
      double magnitude = 0.0;
      for (double ci : c) magnitude = magnitude * std::abs(r) + std::abs(ci);
      // In rounding units of p's scale: polishing stops at 1 unit (below that the computed p is
      // noise); evaluating the residual here adds a few more (at most 2(2n+1) in the worst case).
      worst = std::max(worst, std::abs(p(r)) / (kEps * magnitude));
    }
  }
  EXPECT_LE(worst, 16.0);
}

TEST(PolynomialRoots, CloseButDistinctRootsStayDistinct) {
  const auto r = Polynomial::from_roots(std::vector<Complex>{-1.0, -1.0 - 1e-5}).roots();
  ASSERT_EQ(r.size(), 2U);
  EXPECT_NEAR(std::abs(r[0] - r[1]), 1e-5, 1e-9);
}

TEST(PolynomialRoots, ExtremeScalesDoNotMergeOrOverflow) {
  // s^2 + 1e200 s + 1: roots -1e-200 and -1e200; evaluating p near the average overflows, which
  // must not be mistaken for a double root.
  const auto r = Polynomial({1.0, 1e200, 1.0}).roots();
  ASSERT_EQ(r.size(), 2U);
  EXPECT_NEAR(r[0].real() / -1e-200, 1.0, 1e-14);
  EXPECT_NEAR(r[1].real() / -1e200, 1.0, 1e-14);
  // 1e-300 s^2 + s + 1e300: complex roots of modulus 1e300, computed after scaling s by a power of
  // two (the unscaled companion matrix would hold 1e600).
  const auto big = Polynomial({1e-300, 1.0, 1e300}).roots();
  ASSERT_EQ(big.size(), 2U);
  EXPECT_NEAR(big[0].real() / -5e299, 1.0, 1e-14);
  EXPECT_NEAR(big[0].imag() / (std::sqrt(3.0) * 5e299), 1.0, 1e-14);
  EXPECT_EQ(big[1], std::conj(big[0]));
  // Roots beyond the double range are an error, not infinities or a failed iteration.
  EXPECT_THROW((void)Polynomial({1e-320, 1.0, 1.0}).roots(), std::invalid_argument);
  EXPECT_THROW((void)Polynomial({1e-300, 1e300, 1.0}).roots(), std::invalid_argument);
  // A tiny leading coefficient: roots -1 and -1e300.
  const auto t = Polynomial({1e-300, 1.0, 1.0}).roots();
  ASSERT_EQ(t.size(), 2U);
  EXPECT_NEAR(t[0].real(), -1.0, 1e-15);
  EXPECT_NEAR(t[1].real() / -1e300, 1.0, 1e-14);
}

TEST(PolynomialRoots, UnchangedByScalingCoefficientsAndScaleWithTheVariable) {
  // Units: multiplying p by a constant (e.g. mm -> m on both sides) leaves the roots; substituting
  // s = sigma t (time unit change) divides them by sigma.
  const auto& c = test::reference_case("polynomial_roots", "thesis_ppi_denominator");
  const std::vector<double> coeffs = c.at("coefficients").get<std::vector<double>>();
  const std::vector<Complex> base = Polynomial(coeffs).roots();
  std::vector<double> scaled = coeffs;
  for (double& v : scaled) v *= 1e-3;
  EXPECT_LE(worst_relative_error(Polynomial(scaled).roots(), base), 4 * kEps);
  const double sigma = 1e3;  // s in rad/s -> rad/ms
  std::vector<double> substituted = coeffs;
  for (std::size_t i = 0; i < substituted.size(); ++i)
    substituted[i] *= std::pow(sigma, static_cast<double>(coeffs.size() - 1 - i));
  std::vector<Complex> expected;
  for (const Complex& z : base) expected.push_back(z / sigma);
  EXPECT_LE(worst_relative_error(Polynomial(substituted).roots(), expected), 16 * kEps);
}

TEST(PolynomialRoots, OrderIsAscendingModulusWithPositiveImaginaryFirst) {
  const auto r = Polynomial::from_roots(std::vector<Complex>{-10.0, {-1.0, -1.0}, {-1.0, 1.0}, -0.5}).roots();
  ASSERT_EQ(r.size(), 4U);
  EXPECT_NEAR(r[0].real(), -0.5, 1e-15);
  EXPECT_GT(r[1].imag(), 0.0);
  EXPECT_EQ(r[2], std::conj(r[1]));
  EXPECT_NEAR(r[3].real(), -10.0, 1e-14);
}

}  // namespace
}  // namespace servotwin::core
