#pragma once
// Argument checks shared by the tuning sources: each throws core::InputError naming the parameter.
#include <complex>
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace servotwin::tuning::detail {

/// %.10g of a value (messages).
std::string show(double value);
/// "a ± bj" of a complex root (messages).
std::string show(std::complex<double> root);

/// finite and > 0.
void require_positive(double value, const std::string& field, const std::string& what = "a value");
/// finite and >= 0.
void require_non_negative(double value, const std::string& field, const std::string& what = "a value");
/// finite.
void require_finite(double value, const std::string& field);
/// finite and > 1 (a resonance ratio).
void require_ratio(double r, const std::string& field);
/// ω* > 0 and ζ* > 0, both finite.
void require_pair(double omega_star, double zeta_star);
/// A frequency grid's settings as the analyses take them (fields named under `prefix`, e.g.
/// "options."): 0 < omega_min < omega_max, 2 .. 1e6 points, rel_tol in [1e-12, 0.1].
void require_grid(double omega_min, double omega_max, std::size_t grid_points, double rel_tol,
                  const std::string& prefix);

/// Eigenvalues of a compensator's A by modulus, each conjugate pair with the positive imaginary
/// part first (stable order for files and reports).
std::vector<std::complex<double>> sorted_poles(const Eigen::MatrixXd& a);

}  // namespace servotwin::tuning::detail
