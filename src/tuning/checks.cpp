#include "checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "servotwin/core/error.hpp"

namespace servotwin::tuning::detail {

std::string show(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

std::string show(std::complex<double> root) {
  if (root.imag() == 0.0) return show(root.real());
  return show(root.real()) + (root.imag() < 0.0 ? " - " : " + ") + show(std::abs(root.imag())) + "j";
}

void require_positive(double value, const std::string& field, const std::string& what) {
  if (!std::isfinite(value) || value <= 0.0)
    throw core::InputError(core::at_field(field), "expected " + what + " > 0, got " + show(value));
}

void require_non_negative(double value, const std::string& field, const std::string& what) {
  if (!std::isfinite(value) || value < 0.0)
    throw core::InputError(core::at_field(field), "expected " + what + " >= 0, got " + show(value));
}

void require_finite(double value, const std::string& field) {
  if (!std::isfinite(value)) throw core::InputError(core::at_field(field), "expected a finite value, got " + show(value));
}

void require_ratio(double r, const std::string& field) {
  if (!std::isfinite(r) || r <= 1.0)
    throw core::InputError(core::at_field(field),
                           "expected a resonance ratio r = wn/wz > 1 (collocated two-mass plant), got " + show(r));
}

void require_pair(double omega_star, double zeta_star) {
  require_positive(omega_star, "omega_star", "a bandwidth");
  require_positive(zeta_star, "zeta_star", "a damping ratio");
}

void require_grid(double omega_min, double omega_max, std::size_t grid_points, double rel_tol, const std::string& prefix) {
  require_positive(omega_min, prefix + "omega_min", "a grid start");
  require_positive(omega_max, prefix + "omega_max", "a grid end");
  if (!(omega_max > omega_min))
    throw core::InputError(core::at_field(prefix + "omega_max"), "expected omega_max > omega_min, got " + show(omega_max));
  if (grid_points < 2 || grid_points > 1000000)
    throw core::InputError(core::at_field(prefix + "grid_points"), "expected 2 .. 1e6 grid points");
  if (!(rel_tol >= 1e-12 && rel_tol <= 0.1))
    throw core::InputError(core::at_field(prefix + "rel_tol"), "expected a tolerance in [1e-12, 0.1], got " + show(rel_tol));
}

std::vector<std::complex<double>> sorted_poles(const Eigen::MatrixXd& a) {
  using Complex = std::complex<double>;
  const Eigen::VectorXcd e = a.eigenvalues();
  std::vector<Complex> out(e.data(), e.data() + e.size());
  std::sort(out.begin(), out.end(), [](Complex x, Complex y) {
    if (std::abs(std::abs(x) - std::abs(y)) > 1e-12 * std::max(1.0, std::abs(x))) return std::abs(x) < std::abs(y);
    return x.imag() > y.imag();
  });
  return out;
}

}  // namespace servotwin::tuning::detail
