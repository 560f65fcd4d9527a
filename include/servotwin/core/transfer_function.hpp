#pragma once
/// \file
/// Continuous-time SISO transfer functions G(s) = num(s)/den(s) and their frequency responses.
/// Frequencies are in rad/s inside the library (design.md, "Units").

#include <complex>
#include <span>
#include <vector>

#include "servotwin/core/polynomial.hpp"

namespace servotwin::core {

/// Continuous-time transfer function num(s)/den(s). Common factors are never cancelled
/// implicitly (series/parallel/feedback return the plain polynomial products, like scipy and
/// python-control).
///
/// Errors: bad arguments are programming errors in core and throw std::invalid_argument; readers
/// of user files check coefficients first and report them as core::InputError.
class TransferFunction {
 public:
  /// Throws std::invalid_argument when `den` is the zero polynomial or a coefficient is not finite.
  TransferFunction(Polynomial num, Polynomial den);

  [[nodiscard]] const Polynomial& num() const noexcept { return num_; }
  [[nodiscard]] const Polynomial& den() const noexcept { return den_; }

  /// G(s) at a complex point. For |s| > 1 both polynomials are evaluated in 1/s with reversed
  /// coefficients, so high degrees and high frequencies neither overflow nor lose the leading
  /// terms. At a pole the result is infinite or NaN.
  [[nodiscard]] std::complex<double> operator()(std::complex<double> s) const noexcept;
  /// G(j omega), evaluated with real arithmetic (even and odd parts as polynomials in -omega^2),
  /// scaled like operator() above.
  [[nodiscard]] std::complex<double> frequency_response(double omega_rad_s) const noexcept;
  /// G(j omega) on a grid of frequencies [rad/s].
  [[nodiscard]] std::vector<std::complex<double>> frequency_response(
      std::span<const double> omega_rad_s) const;

  [[nodiscard]] std::vector<std::complex<double>> poles() const { return den_.roots(); }
  [[nodiscard]] std::vector<std::complex<double>> zeros() const { return num_.roots(); }
  /// G(0); +-infinity when the denominator vanishes at s = 0 and the numerator does not.
  [[nodiscard]] double dc_gain() const noexcept;
  /// deg(num) <= deg(den).
  [[nodiscard]] bool is_proper() const noexcept;

  /// Same function with the denominator scaled to leading coefficient 1.
  [[nodiscard]] TransferFunction normalized() const;

 private:
  Polynomial num_;
  Polynomial den_;
};

/// a(s) * b(s).
TransferFunction series(const TransferFunction& a, const TransferFunction& b);
/// a(s) + b(s).
TransferFunction parallel(const TransferFunction& a, const TransferFunction& b);
/// Closed loop of forward path g with feedback path h: g / (1 - sign * g * h) =
/// ng dh / (dg dh - sign ng nh); sign = -1 (default) is negative feedback. Throws
/// std::invalid_argument for a sign other than +-1 or when the closed-loop denominator vanishes
/// identically.
TransferFunction feedback(const TransferFunction& g, const TransferFunction& h, int sign = -1);

/// Logarithmically spaced grid of `count` values from `first` to `last` inclusive (both finite and
/// > 0, else std::invalid_argument); the end points are exactly `first` and `last`.
std::vector<double> log_space(double first, double last, std::size_t count);

/// Natural frequency and damping of one continuous-time root.
struct ModalInfo {
  std::complex<double> root;  ///< the root in the s-plane [rad/s]
  double omega_rad_s = 0.0;   ///< |root|
  double freq_hz = 0.0;       ///< |root| / 2 pi
  double zeta = 0.0;          ///< -Re(root)/|root| (1 for a stable real root, -1 for an unstable one)
};
/// Modal data of an s-plane root (zeta = 1 by convention for a root at 0).
ModalInfo modal_info(std::complex<double> s_root) noexcept;
/// Modal data of a z-plane root mapped through s = ln(z)/ts (principal branch, so a root on the
/// negative real axis maps to the Nyquist frequency pi/ts); ts must be > 0. A root at z = 0 (a
/// pure delay) has no s-plane image: it is reported with root = -inf, infinite frequency and
/// zeta = 1.
ModalInfo modal_info_discrete(std::complex<double> z_root, double ts) noexcept;

}  // namespace servotwin::core
