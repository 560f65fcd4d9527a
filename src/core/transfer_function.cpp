#include "servotwin/core/transfer_function.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace servotwin::core {

namespace {

using Complex = std::complex<double>;

void require_finite(const Polynomial& p, const char* what) {
  for (double v : p.coefficients())
    if (!std::isfinite(v))
      throw std::invalid_argument(std::string("TransferFunction: ") + what + " coefficients must be finite");
}

/// value * z^k by k successive multiplications (or divisions): the intermediate results lie between
/// `value` and the result, so nothing under- or overflows unless the result itself does (forming
/// z^k first would, e.g. 1e39^-8 is subnormal although 1e16 * 1e39^-8 is not). k is the relative
/// degree, a small number.
template <typename T>
Complex times_power(Complex value, T z, int k) noexcept {
  for (int i = 0; i < k; ++i) value *= z;
  for (int i = 0; i > k; --i) value /= z;
  return value;
}

/// Horner evaluation; `reversed` evaluates the polynomial with its coefficient order reversed.
Complex horner(std::span<const double> c, Complex z, bool reversed) noexcept {
  Complex p = 0.0;
  if (reversed)
    for (auto it = c.rbegin(); it != c.rend(); ++it) p = p * z + *it;
  else
    for (double ci : c) p = p * z + ci;
  return p;
}

/// p(j nu) with real arithmetic: even powers give the real part and odd powers the imaginary
/// part, each a real polynomial in x = -nu^2 (half the multiplications of complex Horner).
Complex horner_imaginary_axis(std::span<const double> c, double nu, bool reversed) noexcept {
  const double x = -nu * nu;
  double even = 0.0;
  double odd = 0.0;
  const std::size_t n = c.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double ci = reversed ? c[n - 1 - i] : c[i];
    const std::size_t power = n - 1 - i;
    if (power % 2 == 0) even = even * x + ci;
    else odd = odd * x + ci;
  }
  return {even, odd * nu};
}

/// j^k for an integer k.
Complex j_power(int k) noexcept {
  switch (((k % 4) + 4) % 4) {
    case 0: return {1.0, 0.0};
    case 1: return {0.0, 1.0};
    case 2: return {-1.0, 0.0};
    default: return {0.0, -1.0};
  }
}

}  // namespace

TransferFunction::TransferFunction(Polynomial num, Polynomial den) : num_(std::move(num)), den_(std::move(den)) {
  if (den_.is_zero()) throw std::invalid_argument("TransferFunction: the denominator is the zero polynomial");
  require_finite(num_, "numerator");
  require_finite(den_, "denominator");
}

// For |s| > 1 both polynomials are evaluated in 1/s with reversed coefficients,
//   G(s) = s^(m-n) num_rev(1/s) / den_rev(1/s),
// so no power of s larger than 1 in modulus is ever formed: no overflow at high degree or high
// frequency, and the dominant (leading) coefficients are added last, where Horner is most exact.
std::complex<double> TransferFunction::operator()(std::complex<double> s) const noexcept {
  if (num_.is_zero()) return 0.0;
  if (std::abs(s) <= 1.0) return horner(num_.coefficients(), s, false) / horner(den_.coefficients(), s, false);
  const Complex w = 1.0 / s;
  const Complex ratio = horner(num_.coefficients(), w, true) / horner(den_.coefficients(), w, true);
  return times_power(ratio, s, num_.degree() - den_.degree());
}

std::complex<double> TransferFunction::frequency_response(double omega_rad_s) const noexcept {
  if (num_.is_zero()) return 0.0;
  const double omega = omega_rad_s;
  if (std::abs(omega) <= 1.0)
    return horner_imaginary_axis(num_.coefficients(), omega, false) /
           horner_imaginary_axis(den_.coefficients(), omega, false);
  // 1/(j omega) = j (-1/omega): still on the imaginary axis.
  const double nu = -1.0 / omega;
  const Complex ratio = horner_imaginary_axis(num_.coefficients(), nu, true) /
                        horner_imaginary_axis(den_.coefficients(), nu, true);
  const int excess = num_.degree() - den_.degree();
  return j_power(excess) * times_power(ratio, omega, excess);
}

std::vector<std::complex<double>> TransferFunction::frequency_response(std::span<const double> omega_rad_s) const {
  std::vector<Complex> out(omega_rad_s.size());
  for (std::size_t i = 0; i < omega_rad_s.size(); ++i) out[i] = frequency_response(omega_rad_s[i]);
  return out;
}

double TransferFunction::dc_gain() const noexcept {
  if (num_.is_zero()) return 0.0;
  // G(0) as the limit s -> 0: cancel common factors s first, then G ~ n0 / (d_k s^k) from the right.
  const std::span<const double> n = num_.coefficients();
  const std::span<const double> d = den_.coefficients();
  std::size_t n_zero = 0;
  while (n[n.size() - 1 - n_zero] == 0.0) ++n_zero;
  std::size_t d_zero = 0;
  while (d[d.size() - 1 - d_zero] == 0.0) ++d_zero;
  const double n0 = n[n.size() - 1 - n_zero];
  const double d0 = d[d.size() - 1 - d_zero];
  if (n_zero > d_zero) return 0.0;
  if (n_zero == d_zero) return n0 / d0;
  return (n0 / d0 > 0.0) ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
}

bool TransferFunction::is_proper() const noexcept { return num_.degree() <= den_.degree(); }

namespace {
/// Division (not multiplication by the reciprocal) so that the result is bit-identical to
/// scipy.signal.normalize, which tf2ss fixtures are compared with.
Polynomial divided(const Polynomial& p, double divisor) {
  std::vector<double> c(p.coefficients().begin(), p.coefficients().end());
  for (double& v : c) v /= divisor;
  return Polynomial(std::move(c));
}
}  // namespace

TransferFunction TransferFunction::normalized() const {
  const double lead = den_.leading();
  return {divided(num_, lead), divided(den_, lead)};
}

TransferFunction series(const TransferFunction& a, const TransferFunction& b) {
  return {a.num() * b.num(), a.den() * b.den()};
}

TransferFunction parallel(const TransferFunction& a, const TransferFunction& b) {
  return {a.num() * b.den() + b.num() * a.den(), a.den() * b.den()};
}

TransferFunction feedback(const TransferFunction& g, const TransferFunction& h, int sign) {
  if (sign != 1 && sign != -1) throw std::invalid_argument("feedback: sign must be +1 or -1");
  Polynomial den = g.den() * h.den() - static_cast<double>(sign) * (g.num() * h.num());
  if (den.is_zero()) throw std::invalid_argument("feedback: the closed loop is singular (1 - sign g h == 0)");
  return {g.num() * h.den(), std::move(den)};
}

std::vector<double> log_space(double first, double last, std::size_t count) {
  if (!(first > 0.0) || !(last > 0.0) || !std::isfinite(first) || !std::isfinite(last))
    throw std::invalid_argument("log_space: first and last must be finite and > 0");
  std::vector<double> out(count);
  if (count == 0) return out;
  out.front() = first;
  if (count == 1) return out;
  const double log_first = std::log(first);
  const double step = (std::log(last) - log_first) / static_cast<double>(count - 1);
  for (std::size_t i = 1; i + 1 < count; ++i) out[i] = std::exp(log_first + step * static_cast<double>(i));
  out.back() = last;
  return out;
}

ModalInfo modal_info(std::complex<double> s_root) noexcept {
  ModalInfo info;
  info.root = s_root;
  info.omega_rad_s = std::abs(s_root);
  info.freq_hz = info.omega_rad_s / (2.0 * std::numbers::pi);
  info.zeta = info.omega_rad_s == 0.0 ? 1.0 : -s_root.real() / info.omega_rad_s;
  return info;
}

ModalInfo modal_info_discrete(std::complex<double> z_root, double ts) noexcept {
  if (z_root == Complex(0.0, 0.0)) {
    ModalInfo info;
    info.root = Complex(-std::numeric_limits<double>::infinity(), 0.0);
    info.omega_rad_s = std::numeric_limits<double>::infinity();
    info.freq_hz = std::numeric_limits<double>::infinity();
    info.zeta = 1.0;
    return info;
  }
  return modal_info(std::log(z_root) / ts);
}

}  // namespace servotwin::core
