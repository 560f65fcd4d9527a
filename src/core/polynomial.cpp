#include "servotwin/core/polynomial.hpp"

#include "balance.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace servotwin::core {

namespace {

using Complex = std::complex<double>;
constexpr double kEps = std::numeric_limits<double>::epsilon();

std::vector<double> strip_leading_zeros(std::vector<double> c) {
  const auto first_nonzero = std::find_if(c.begin(), c.end(), [](double v) { return v != 0.0; });
  c.erase(c.begin(), first_nonzero);
  return c;
}

void require_finite_for(std::span<const double> c, const char* message) {
  for (double v : c)
    if (!std::isfinite(v)) throw std::invalid_argument(message);
}

void require_finite(std::span<const double> c) { require_finite_for(c, "Polynomial::roots: coefficients must be finite"); }

/// Value and derivative of p at z, with magnitude = sum |c_i| |z|^(n-i), the scale of the
/// rounding errors of the Horner recurrence: |fl(p(z)) - p(z)| <= gamma_{2n} * magnitude (Higham,
/// "Accuracy and Stability of Numerical Algorithms", eq. 5.3; doubled for complex arithmetic)
/// is `error_bound`.
struct HornerResult {
  Complex value;
  Complex derivative;
  double magnitude;
  double error_bound;
};

HornerResult horner_with_bound(std::span<const double> c, Complex z) noexcept {
  Complex p = 0.0;
  Complex dp = 0.0;
  double abs_sum = 0.0;
  const double az = std::abs(z);
  for (double ci : c) {
    dp = dp * z + p;
    p = p * z + ci;
    abs_sum = abs_sum * az + std::abs(ci);
  }
  const double n = static_cast<double>(c.size());
  return {p, dp, abs_sum, 2.0 * (2.0 * n + 1.0) * kEps * abs_sum};
}

/// Coefficients of the k-th derivative.
std::vector<double> derivative_coefficients(std::span<const double> c, int k) {
  std::vector<double> d(c.begin(), c.end());
  for (int j = 0; j < k && !d.empty(); ++j) {
    const std::size_t n = d.size() - 1;
    std::vector<double> next(n);
    for (std::size_t i = 0; i < n; ++i) next[i] = d[i] * static_cast<double>(n - i);
    d = std::move(next);
  }
  return d;
}

/// Eigenvalues of the balanced companion matrix of the monic version of c (degree >= 1, c[n] != 0).
std::vector<Complex> companion_eigenvalues(std::span<const double> c) {
  const auto n = static_cast<Eigen::Index>(c.size() - 1);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) companion(0, j) = -c[static_cast<std::size_t>(j + 1)] / c[0];
  for (Eigen::Index i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  // Balancing makes the companion eigenvalues backward stable with respect to the polynomial
  // coefficients even when they span many decades (Edelman & Murakami 1995).
  detail::balance(companion);
  Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success)
    throw std::runtime_error("Polynomial::roots: eigenvalue iteration did not converge");
  std::vector<Complex> out(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = solver.eigenvalues()(i);
  return out;
}

/// Newton steps on p while they reduce |p|; stops once |p| is below one rounding unit of its
/// scale, eps * sum |c_i| |z|^(n-i): there the computed p is rounding noise and further steps
/// would only follow it (which matters at multiple roots, where Newton is slow anyway).
Complex polish(std::span<const double> c, Complex z) {
  HornerResult at = horner_with_bound(c, z);
  for (int iteration = 0; iteration < 50; ++iteration) {
    if (std::abs(at.value) <= kEps * at.magnitude || at.derivative == Complex(0.0)) break;
    Complex next = z - at.value / at.derivative;
    if (z.imag() == 0.0) next.imag(0.0);  // a real root stays real (exactly so for real arithmetic)
    const HornerResult at_next = horner_with_bound(c, next);
    if (!(std::abs(at_next.value) < std::abs(at.value))) break;
    z = next;
    at = at_next;
  }
  return z;
}

/// A cluster of m computed roots around a root of multiplicity m: the individual roots scatter
/// on a circle of radius ~ eps^(1/m), but their centroid is accurate to ~ eps. The centroid is a
/// simple root of p^(m-1), on which Newton converges quadratically. The cluster is replaced by m
/// copies of that point when p, p', ..., p^(m-1) all vanish there to rounding accuracy, i.e. when
/// the polynomial is within rounding of one with an m-fold root there.
struct ClusterResult {
  bool accepted = false;
  Complex center;
};

ClusterResult try_cluster(const std::vector<std::vector<double>>& derivatives, const std::vector<Complex>& members) {
  const auto m = members.size();
  Complex center = 0.0;
  for (const Complex& z : members) center += z;
  center /= static_cast<double>(m);
  center = polish(derivatives[m - 1], center);
  constexpr double tolerance_factor = 8.0;
  for (std::size_t k = 0; k < m; ++k) {
    const HornerResult at = horner_with_bound(derivatives[k], center);
    // Overflow makes both sides infinite; such a test proves nothing, so the cluster stays.
    if (!std::isfinite(at.error_bound) || !(std::abs(at.value) <= tolerance_factor * at.error_bound)) return {};
  }
  return {true, center};
}

/// Replaces clusters of computed roots that represent one multiple root by the cluster's
/// refined centre (see try_cluster). Clusters are the m nearest roots to a seed root; the largest
/// accepted m wins.
void merge_multiple_roots(std::span<const double> c, std::vector<Complex>& roots) {
  const std::size_t n = roots.size();
  if (n < 2) return;
  // Multiplicities above ~12 are not resolvable in double precision (eps^(1/12) ~ 0.05).
  constexpr std::size_t max_multiplicity = 12;
  std::vector<std::vector<double>> derivatives{std::vector<double>(c.begin(), c.end())};
  for (std::size_t k = 1; k < std::min(n, max_multiplicity); ++k)
    derivatives.push_back(derivative_coefficients(derivatives.back(), 1));
  std::vector<bool> done(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    if (done[i]) continue;
    std::vector<std::size_t> candidates;
    for (std::size_t j = 0; j < n; ++j)
      if (!done[j]) candidates.push_back(j);
    std::sort(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) {
      return std::abs(roots[a] - roots[i]) < std::abs(roots[b] - roots[i]);
    });
    for (std::size_t m = std::min(candidates.size(), max_multiplicity); m >= 2; --m) {
      std::vector<Complex> members;
      for (std::size_t k = 0; k < m; ++k) members.push_back(roots[candidates[k]]);
      // Only clusters that are tight compared with the distance to the next root qualify: a
      // perturbed multiple root spreads over a ring of radius ~ (eps cond)^(1/m), far smaller
      // than the gap to the other roots, whereas evenly spread roots (e.g. roots of unity) are
      // rejected here without the cost of the derivative test.
      constexpr double separation_factor = 4.0;
      double radius = 0.0;
      for (const Complex& z : members) radius = std::max(radius, std::abs(z - roots[i]));
      if (m < candidates.size() && std::abs(roots[candidates[m]] - roots[i]) <= separation_factor * radius) continue;
      const ClusterResult cluster = try_cluster(derivatives, members);
      if (!cluster.accepted) continue;
      for (std::size_t k = 0; k < m; ++k) {
        roots[candidates[k]] = cluster.center;
        done[candidates[k]] = true;
      }
      break;
    }
    done[i] = true;
  }
}

/// Roots of a real polynomial with a nonzero constant term and degree >= 1.
std::vector<Complex> unscaled_nonzero_roots(std::span<const double> c) {
  if (c.size() == 2) return {Complex(-c[1] / c[0], 0.0)};
  std::vector<Complex> eig = companion_eigenvalues(c);
  // Eigenvalues of a real matrix come as real values and exact conjugate pairs; polish one member
  // of each pair and mirror it, so the pairs stay exact.
  std::vector<Complex> roots;
  roots.reserve(eig.size());
  for (const Complex& z : eig) {
    if (z.imag() < 0.0) continue;
    const Complex polished = polish(c, z);
    roots.push_back(polished);
    if (z.imag() > 0.0) roots.push_back(std::conj(polished));
  }
  merge_multiple_roots(c, roots);
  // Real coefficients: a cluster centre of a conjugate-symmetric cluster is real up to rounding of
  // the averaging; restore exact symmetry by mirroring the upper half plane.
  std::vector<Complex> symmetric;
  symmetric.reserve(roots.size());
  std::vector<Complex> lower;
  for (const Complex& z : roots) {
    const double tiny_imag = 4.0 * kEps * std::abs(z);
    if (std::abs(z.imag()) <= tiny_imag) symmetric.emplace_back(z.real(), 0.0);
    else if (z.imag() > 0.0) symmetric.push_back(z);
    else lower.push_back(z);
  }
  const std::size_t upper_count =
      static_cast<std::size_t>(std::count_if(symmetric.begin(), symmetric.end(), [](Complex z) { return z.imag() > 0.0; }));
  if (upper_count == lower.size()) {
    for (const Complex& z : std::vector<Complex>(symmetric))
      if (z.imag() > 0.0) symmetric.push_back(std::conj(z));
    return symmetric;
  }
  return roots;  // asymmetric only if something above went wrong; keep what was computed
}

/// Roots of a real polynomial with a nonzero constant term and degree >= 1, computed for the
/// variable t = s / 2^e with 2^e near the geometric mean of the root moduli, |c_n / c_0|^(1/n), and
/// the coefficients rescaled by a power of two so the largest is near 1. Scaling by powers of two
/// is exact, so this changes no digit of an ordinary result; it keeps the companion matrix and
/// the Horner evaluations free of overflow when the coefficients span more than the exponent
/// range (e.g. 1e-300 s^2 + s + 1e300, whose roots ~1e300 are representable).
std::vector<Complex> nonzero_roots(std::span<const double> c) {
  const std::size_t n = c.size() - 1;
  const int e = static_cast<int>(std::lround(static_cast<double>(std::ilogb(c[n]) - std::ilogb(c[0])) / static_cast<double>(n)));
  int shift = std::numeric_limits<int>::min();
  for (std::size_t i = 0; i <= n; ++i)
    if (c[i] != 0.0) shift = std::max(shift, std::ilogb(c[i]) + static_cast<int>(n - i) * e);
  std::vector<double> scaled(c.size());
  for (std::size_t i = 0; i <= n; ++i) scaled[i] = std::ldexp(c[i], static_cast<int>(n - i) * e - shift);
  // Only when the root moduli themselves span more than the exponent range does the leading or
  // constant coefficient underflow here; no single scaling can represent such a polynomial.
  if (scaled.front() == 0.0 || scaled.back() == 0.0)
    throw std::invalid_argument("Polynomial::roots: the coefficients span more than the floating-point range");
  std::vector<Complex> roots = unscaled_nonzero_roots(scaled);
  for (Complex& z : roots) {
    z = Complex(std::ldexp(z.real(), e), std::ldexp(z.imag(), e));
    if (!std::isfinite(z.real()) || !std::isfinite(z.imag()))
      throw std::invalid_argument("Polynomial::roots: a root lies beyond the floating-point range");
  }
  return roots;
}

/// Ascending modulus, then ascending real part, then positive imaginary part first, so conjugate
/// pairs are adjacent and the order is reproducible.
bool root_order(const Complex& a, const Complex& b) {
  const double ma = std::abs(a);
  const double mb = std::abs(b);
  if (ma != mb) return ma < mb;
  if (a.real() != b.real()) return a.real() < b.real();
  return a.imag() > b.imag();
}

}  // namespace

Polynomial::Polynomial(std::vector<double> coefficients_descending)
    : c_(strip_leading_zeros(std::move(coefficients_descending))) {}

Polynomial::Polynomial(std::initializer_list<double> coefficients_descending)
    : Polynomial(std::vector<double>(coefficients_descending)) {}

Polynomial Polynomial::from_roots(std::span<const std::complex<double>> roots, double gain) {
  constexpr double pair_tolerance = 1e-9;
  std::vector<double> c{gain};
  auto multiply = [&c](std::initializer_list<double> factor) {
    std::vector<double> out(c.size() + factor.size() - 1, 0.0);
    std::size_t i = 0;
    for (double a : c) {
      std::size_t j = 0;
      for (double b : factor) out[i + j++] += a * b;
      ++i;
    }
    c = std::move(out);
  };
  std::vector<bool> used(roots.size(), false);
  for (std::size_t i = 0; i < roots.size(); ++i) {
    if (used[i]) continue;
    used[i] = true;
    const Complex r = roots[i];
    if (!std::isfinite(r.real()) || !std::isfinite(r.imag()))
      throw std::invalid_argument("Polynomial::from_roots: roots must be finite");
    const double scale = std::abs(r);
    if (std::abs(r.imag()) <= pair_tolerance * scale) {
      multiply({1.0, -r.real()});
      continue;
    }
    std::size_t partner = roots.size();
    for (std::size_t j = i + 1; j < roots.size(); ++j) {
      if (!used[j] && std::abs(roots[j] - std::conj(r)) <= pair_tolerance * scale) {
        partner = j;
        break;
      }
    }
    if (partner == roots.size())
      throw std::invalid_argument("Polynomial::from_roots: complex root without its conjugate");
    used[partner] = true;
    // Average the pair so the quadratic factor is the same whichever member came first.
    const Complex mean = 0.5 * (r + std::conj(roots[partner]));
    multiply({1.0, -2.0 * mean.real(), std::norm(mean)});
  }
  return Polynomial(std::move(c));
}

int Polynomial::degree() const noexcept { return static_cast<int>(c_.size()) - 1; }

double Polynomial::coefficient_of_power(int k) const noexcept {
  if (k < 0 || k > degree()) return 0.0;
  return c_[static_cast<std::size_t>(degree() - k)];
}

double Polynomial::operator()(double x) const noexcept {
  double p = 0.0;
  for (double ci : c_) p = p * x + ci;
  return p;
}

std::complex<double> Polynomial::operator()(std::complex<double> x) const noexcept {
  Complex p = 0.0;
  for (double ci : c_) p = p * x + ci;
  return p;
}

Polynomial Polynomial::derivative() const { return Polynomial(derivative_coefficients(c_, 1)); }

std::vector<std::complex<double>> Polynomial::roots() const {
  require_finite(c_);
  if (c_.size() <= 1) return {};
  std::size_t zero_roots = 0;
  while (zero_roots + 1 < c_.size() && c_[c_.size() - 1 - zero_roots] == 0.0) ++zero_roots;
  const std::span<const double> reduced(c_.data(), c_.size() - zero_roots);
  std::vector<Complex> out;
  if (reduced.size() >= 2) out = nonzero_roots(reduced);
  out.insert(out.end(), zero_roots, Complex(0.0, 0.0));
  std::sort(out.begin(), out.end(), root_order);
  return out;
}

Polynomial operator+(const Polynomial& a, const Polynomial& b) {
  const std::span<const double> ca = a.coefficients();
  const std::span<const double> cb = b.coefficients();
  const std::size_t n = std::max(ca.size(), cb.size());
  std::vector<double> out(n, 0.0);
  for (std::size_t i = 0; i < ca.size(); ++i) out[n - ca.size() + i] += ca[i];
  for (std::size_t i = 0; i < cb.size(); ++i) out[n - cb.size() + i] += cb[i];
  return Polynomial(std::move(out));
}

Polynomial operator-(const Polynomial& a, const Polynomial& b) { return a + (-1.0) * b; }

Polynomial operator*(const Polynomial& a, const Polynomial& b) {
  const std::span<const double> ca = a.coefficients();
  const std::span<const double> cb = b.coefficients();
  if (ca.empty() || cb.empty()) return {};
  std::vector<double> out(ca.size() + cb.size() - 1, 0.0);
  for (std::size_t i = 0; i < ca.size(); ++i)
    for (std::size_t j = 0; j < cb.size(); ++j) out[i + j] += ca[i] * cb[j];
  return Polynomial(std::move(out));
}

Polynomial operator*(double k, const Polynomial& a) {
  std::vector<double> out(a.coefficients().begin(), a.coefficients().end());
  for (double& v : out) v *= k;
  return Polynomial(std::move(out));
}

namespace {

/// Row width of the Routh array of a degree-n polynomial (the first row c0, c2, ..., padded).
constexpr std::size_t kRouthStackWidth = 32;  // degree <= 63 on the stack

/// Rescales a Routh row by a power of two when its largest entry leaves [2^-100, 2^100]: a positive
/// factor on one row scales every later row that depends on it by a positive factor (the ratio
/// r_{i-2}[0] / r_{i-1}[0] absorbs the other), so no first-column sign changes.
void keep_row_in_range(std::span<double> row) noexcept {
  double largest = 0.0;
  for (double v : row) largest = std::max(largest, std::abs(v));
  constexpr double upper = 0x1p100, lower = 0x1p-100;
  if ((largest <= upper && largest >= lower) || largest == 0.0 || !std::isfinite(largest)) return;
  const double factor = std::ldexp(1.0, -std::ilogb(largest));
  for (double& v : row) v *= factor;
}

/// Routh test on the sign-normalised first two rows `older`, `newer` (width w, zero padded);
/// `next` is scratch of width w.
bool routh_first_column_positive(std::span<double> older, std::span<double> newer, std::span<double> next,
                                 int degree) noexcept {
  const std::size_t w = older.size();
  keep_row_in_range(older);
  keep_row_in_range(newer);
  for (int row = 2; row <= degree; ++row) {
    const double ratio = older[0] / newer[0];
    for (std::size_t j = 0; j + 1 < w; ++j) next[j] = older[j + 1] - ratio * newer[j + 1];
    next[w - 1] = 0.0;
    // A zero or negative first-column entry (NaN included) ends the test: not Hurwitz.
    if (!(next[0] > 0.0)) return false;
    keep_row_in_range(next);
    std::swap(older, newer);
    std::swap(newer, next);
  }
  return true;
}

}  // namespace

bool is_hurwitz(const Polynomial& p) {
  const std::span<const double> c = p.coefficients();
  if (c.empty()) throw std::invalid_argument("is_hurwitz: the zero polynomial has no Hurwitz property");
  require_finite_for(c, "is_hurwitz: coefficients must be finite");
  const int degree = p.degree();
  if (degree == 0) return true;
  // Every coefficient of a Hurwitz polynomial has the leading coefficient's sign (a product of
  // positive linear and quadratic factors); this necessary condition also settles rows 0 and 1.
  const double sign = c[0] > 0.0 ? 1.0 : -1.0;
  for (double v : c)
    if (!(sign * v > 0.0)) return false;
  if (degree <= 2) return true;  // positive coefficients suffice up to degree 2
  const std::size_t w = static_cast<std::size_t>(degree) / 2 + 1;
  std::array<double, 3 * kRouthStackWidth> stack;  // not zeroed: every used entry is written below
  std::vector<double> heap;
  double* storage = stack.data();
  if (w > kRouthStackWidth) {
    heap.assign(3 * w, 0.0);
    storage = heap.data();
  }
  const std::span<double> row0(storage, w), row1(storage + w, w), scratch(storage + 2 * w, w);
  for (std::size_t j = 0; j < w; ++j) {
    row0[j] = 2 * j < c.size() ? sign * c[2 * j] : 0.0;
    row1[j] = 2 * j + 1 < c.size() ? sign * c[2 * j + 1] : 0.0;
  }
  return routh_first_column_positive(row0, row1, scratch, degree);
}

}  // namespace servotwin::core
