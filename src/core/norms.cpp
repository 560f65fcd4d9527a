#include "servotwin/core/norms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "balance.hpp"

namespace servotwin::core {

namespace {

using Complex = std::complex<double>;
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

void require(bool condition, const char* message) {
  if (!condition) throw std::invalid_argument(message);
}

void require_tolerance(double rel_tol, const char* who) {
  if (!(rel_tol >= 1e-12 && rel_tol <= 0.1)) throw std::invalid_argument(std::string(who) + ": rel_tol must lie in [1e-12, 0.1]");
}

double sigma_max(const Eigen::MatrixXcd& g) {
  if (g.size() == 1) return std::abs(g(0, 0));
  if (g.size() == 0) return 0.0;
  return Eigen::JacobiSVD<Eigen::MatrixXcd>(g).singularValues()(0);
}

double sigma_max(const Eigen::MatrixXd& g) {
  if (g.size() == 0) return 0.0;
  return Eigen::JacobiSVD<Eigen::MatrixXd>(g).singularValues()(0);
}

/// The system with A balanced and B, C scaled to equal norms: same transfer matrix, and the
/// Hamiltonian's blocks of comparable size whatever the state and signal units.
StateSpace scaled_for_norm(const StateSpace& sys) {
  StateSpace s = detail::balanced(sys);
  const double nb = s.B.norm(), nc = s.C.norm();
  if (nb > 0.0 && nc > 0.0) {
    const double beta = std::sqrt(nc / nb);
    s.B *= beta;
    s.C /= beta;
  }
  return s;
}

/// Tracks the largest sigma_max seen and where.
struct BestGain {
  double value = -1.0;
  double omega = 0.0;
  void offer(double v, double w) {
    if (v > value) {
      value = v;
      omega = w;
    }
  }
};

/// Frequencies omega >= 0 of the eigenvalues of the Hamiltonian M(gamma) on (or, loosely, near) the
/// imaginary axis, sorted and unique.
std::vector<double> imaginary_axis_crossings(const StateSpace& s, double gamma) {
  const Eigen::Index n = s.states(), m = s.inputs(), p = s.outputs();
  const double g2 = gamma * gamma;
  // R = D^T D - g^2 I and S = D D^T - g^2 I are negative definite for gamma > sigma_max(D).
  const Eigen::MatrixXd minus_r = g2 * Eigen::MatrixXd::Identity(m, m) - s.D.transpose() * s.D;
  const Eigen::MatrixXd minus_s = g2 * Eigen::MatrixXd::Identity(p, p) - s.D * s.D.transpose();
  const Eigen::LLT<Eigen::MatrixXd> r_llt(minus_r), s_llt(minus_s);
  if (r_llt.info() != Eigen::Success || s_llt.info() != Eigen::Success)
    throw std::runtime_error("hinf_norm: gamma^2 I - D^T D is not positive definite (internal error)");
  // R^-1 X = -(-R)^-1 X.
  const Eigen::MatrixXd r_inv_dt_c = -r_llt.solve(s.D.transpose() * s.C);
  const Eigen::MatrixXd r_inv_bt = -r_llt.solve(s.B.transpose());
  const Eigen::MatrixXd s_inv_c = -s_llt.solve(s.C);
  Eigen::MatrixXd h(2 * n, 2 * n);
  const Eigen::MatrixXd m11 = s.A - s.B * r_inv_dt_c;
  h.topLeftCorner(n, n) = m11;
  h.topRightCorner(n, n) = -gamma * s.B * r_inv_bt;
  h.bottomLeftCorner(n, n) = gamma * s.C.transpose() * s_inv_c;
  h.bottomRightCorner(n, n) = -m11.transpose();
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(h, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) throw std::runtime_error("hinf_norm: Hamiltonian eigenvalue iteration did not converge");
  const double absolute = 1e3 * kEps * h.norm();
  std::vector<double> omegas;
  for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i) {
    const Complex lambda = solver.eigenvalues()(i);
    if (lambda.imag() < 0.0) continue;
    if (std::abs(lambda.real()) <= 1e-6 * std::abs(lambda) + absolute) omegas.push_back(lambda.imag());
  }
  std::sort(omegas.begin(), omegas.end());
  omegas.erase(std::unique(omegas.begin(), omegas.end()), omegas.end());
  return omegas;
}

}  // namespace

namespace {

/// The poles of s, each with Re < -100 eps ||A||; std::invalid_argument naming `who` otherwise
/// (the H-infinity norm of an unstable system is infinite).
Eigen::VectorXcd stable_poles(const StateSpace& s, const std::string& who) {
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(s.A, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) throw std::runtime_error(who + ": eigenvalue iteration did not converge");
  const Eigen::VectorXcd poles = solver.eigenvalues();
  const double stability_margin = 100.0 * kEps * s.A.norm();
  for (Eigen::Index i = 0; i < poles.size(); ++i)
    if (!(poles(i).real() < -stability_margin))
      throw std::invalid_argument(who + ": the system is not stable (a pole with Re >= -100 eps ||A||); the H-infinity "
                                        "norm is infinite");
  return poles;
}

/// Where a peak search starts: DC, and each pole's natural and (above the real axis) damped
/// frequency, in that order.
std::vector<double> pole_frequencies(const Eigen::VectorXcd& poles) {
  std::vector<double> omegas{0.0};
  for (const Complex& p : poles) {
    omegas.push_back(std::abs(p));
    if (p.imag() > 0.0) omegas.push_back(p.imag());
  }
  return omegas;
}

/// The midpoint of each interval between consecutive imaginary-axis crossings, the first interval
/// starting at 0: where sigma_max can exceed the gamma the crossings belong to.
std::vector<double> crossing_midpoints(const std::vector<double>& crossings) {
  std::vector<double> midpoints;
  double previous = 0.0;
  for (const double crossing : crossings) {
    if (crossing > previous) midpoints.push_back(0.5 * (previous + crossing));
    previous = crossing;
  }
  return midpoints;
}

}  // namespace

PeakResult hinf_norm(const StateSpace& sys, double rel_tol) {
  require_tolerance(rel_tol, "hinf_norm");
  FrequencyResponseEvaluator check(sys);  // validates shapes and finiteness
  const double sigma_d = sigma_max(sys.D);
  const StateSpace s = scaled_for_norm(sys);
  const Eigen::Index n = s.states();
  if (n == 0 || s.B.norm() == 0.0 || s.C.norm() == 0.0) return {sigma_d, 0.0};  // G = D at every frequency

  const Eigen::VectorXcd poles = stable_poles(s, "hinf_norm");

  FrequencyResponseEvaluator evaluator(s);
  Eigen::MatrixXcd g;
  auto gain_at = [&](double omega) {
    evaluator.evaluate(Complex(0.0, omega), g);
    return sigma_max(g);
  };

  // Lower bound: DC, every pole's natural and damped frequency, and the limit at infinity.
  BestGain best;
  for (const double omega : pole_frequencies(poles)) best.offer(gain_at(omega), omega);
  best.offer(sigma_d, kInf);
  if (best.value == 0.0) {
    // Every entry of G is N_ij(s)/det(sI - A) with deg N_ij < n (D = 0 here). Zero at s = 0 and at
    // +-j omega_k for n/2 + 1 further distinct omega_k means more than n - 1 roots: N_ij = 0.
    const double lo = 0.5 * poles.cwiseAbs().minCoeff(), hi = 2.0 * poles.cwiseAbs().maxCoeff();
    const Eigen::Index count = n / 2 + 2;
    for (Eigen::Index k = 0; k < count; ++k) {
      const double omega = lo * std::pow(hi / lo, static_cast<double>(k + 1) / static_cast<double>(count + 1));
      best.offer(gain_at(omega), omega);
    }
    if (best.value == 0.0) return {0.0, 0.0};
  }

  for (int iteration = 0; iteration < 100; ++iteration) {
    const double gamma = (1.0 + rel_tol) * best.value;
    const std::vector<double> crossings = imaginary_axis_crossings(s, gamma);
    if (crossings.empty()) return {best.value, best.omega};
    // sigma_max > gamma only between crossings; 0 bounds the first interval (sigma_max(G(0)) and
    // sigma_max(D) are <= the lower bound < gamma, so a crossing lost to rounding costs nothing).
    BestGain midpoints;
    for (const double mid : crossing_midpoints(crossings)) midpoints.offer(gain_at(mid), mid);
    best.offer(midpoints.value, midpoints.omega);
    // No midpoint above gamma: the crossings were rounding artefacts of eigenvalues near the axis,
    // and the evaluated gains confirm gamma as an upper bound.
    if (!(midpoints.value > gamma)) return {best.value, best.omega};
  }
  throw std::runtime_error("hinf_norm: the Bruinsma-Steinbuch iteration did not converge");
}

bool hinf_norm_below(const StateSpace& sys, double gamma) {
  if (!std::isfinite(gamma) || !(gamma > 0.0)) throw std::invalid_argument("hinf_norm_below: gamma must be finite and > 0");
  FrequencyResponseEvaluator check(sys);  // validates shapes and finiteness
  if (!(sigma_max(sys.D) < gamma)) return false;
  const StateSpace s = scaled_for_norm(sys);
  const Eigen::Index n = s.states();
  if (n == 0 || s.B.norm() == 0.0 || s.C.norm() == 0.0) return true;  // G = D at every frequency
  const Eigen::VectorXcd poles = stable_poles(s, "hinf_norm_below");
  FrequencyResponseEvaluator evaluator(s);
  Eigen::MatrixXcd g;
  const auto gain_at = [&](double omega) {
    evaluator.evaluate(Complex(0.0, omega), g);
    return sigma_max(g);
  };
  const auto below = [&](double omega) { return gain_at(omega) < gamma; };
  const std::vector<double> probes = pole_frequencies(poles);
  if (!std::all_of(probes.begin(), probes.end(), below)) return false;
  const std::vector<double> midpoints = crossing_midpoints(imaginary_axis_crossings(s, gamma));
  return std::all_of(midpoints.begin(), midpoints.end(), below);
}

namespace {

void check_grid(std::span<const double> grid, std::size_t minimum_size, const char* who) {
  if (grid.size() < minimum_size)
    throw std::invalid_argument(std::string(who) + ": the grid needs at least " + std::to_string(minimum_size) + " point(s)");
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (!std::isfinite(grid[i]) || grid[i] < 0.0) throw std::invalid_argument(std::string(who) + ": grid frequencies must be finite and >= 0");
    if (i > 0 && !(grid[i] > grid[i - 1])) throw std::invalid_argument(std::string(who) + ": the grid must be strictly increasing");
  }
}

double magnitude_of(const std::function<std::complex<double>(double)>& f, double omega, const char* who) {
  const double m = std::abs(f(omega));
  if (std::isnan(m)) throw std::invalid_argument(std::string(who) + ": f returned NaN at omega = " + std::to_string(omega));
  return m;
}

/// Golden-section maximisation of |f| over [lo, hi], in log omega when lo > 0 (peaks of frequency
/// responses are symmetric in log omega, not in omega), until the bracket is below rel_tol relative.
void golden_section(const std::function<std::complex<double>(double)>& f, double lo, double hi, double rel_tol, BestGain& best) {
  const bool logarithmic = lo > 0.0;
  const auto to_omega = [&](double x) { return logarithmic ? std::exp(x) : x; };
  double a = logarithmic ? std::log(lo) : lo;
  double b = logarithmic ? std::log(hi) : hi;
  const double width_tol = logarithmic ? rel_tol : rel_tol * hi;
  const double inv_phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - inv_phi * (b - a), d = a + inv_phi * (b - a);
  double fc = magnitude_of(f, to_omega(c), "peak_on_grid"), fd = magnitude_of(f, to_omega(d), "peak_on_grid");
  best.offer(fc, to_omega(c));
  best.offer(fd, to_omega(d));
  for (int iteration = 0; iteration < 200 && b - a > width_tol; ++iteration) {
    if (fc >= fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - inv_phi * (b - a);
      fc = magnitude_of(f, to_omega(c), "peak_on_grid");
      best.offer(fc, to_omega(c));
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + inv_phi * (b - a);
      fd = magnitude_of(f, to_omega(d), "peak_on_grid");
      best.offer(fd, to_omega(d));
    }
    if (std::isinf(best.value)) return;
  }
}

}  // namespace

PeakResult peak_on_grid(const std::function<std::complex<double>(double)>& f, std::span<const double> omega_grid, double rel_tol) {
  require(static_cast<bool>(f), "peak_on_grid: f is empty");
  require_tolerance(rel_tol, "peak_on_grid");
  check_grid(omega_grid, 1, "peak_on_grid");
  const std::size_t count = omega_grid.size();
  std::vector<double> magnitude(count);
  BestGain best;
  for (std::size_t i = 0; i < count; ++i) {
    magnitude[i] = magnitude_of(f, omega_grid[i], "peak_on_grid");
    best.offer(magnitude[i], omega_grid[i]);
    if (std::isinf(magnitude[i])) return {kInf, omega_grid[i]};
  }
  for (std::size_t i = 0; i < count && count > 1; ++i) {
    const bool above_left = i == 0 || magnitude[i] > magnitude[i - 1];
    const bool not_below_right = i + 1 == count || magnitude[i] >= magnitude[i + 1];
    if (!above_left || !not_below_right) continue;
    golden_section(f, omega_grid[i == 0 ? 0 : i - 1], omega_grid[std::min(i + 1, count - 1)], rel_tol, best);
    if (std::isinf(best.value)) break;
  }
  return {best.value, best.omega};
}

std::optional<double> bandwidth(const std::function<std::complex<double>(double)>& f, std::span<const double> grid, double level_db) {
  require(static_cast<bool>(f), "bandwidth: f is empty");
  require(std::isfinite(level_db) && level_db < 0.0, "bandwidth: level_db must be finite and < 0");
  check_grid(grid, 2, "bandwidth");
  const double reference = magnitude_of(f, grid[0], "bandwidth");
  if (!(reference > 0.0) || !std::isfinite(reference))
    throw std::domain_error("bandwidth: the reference gain |f(grid[0])| is zero or not finite");
  const double threshold = reference * std::pow(10.0, level_db / 20.0);
  const auto below = [&](double omega) { return magnitude_of(f, omega, "bandwidth") < threshold; };
  for (std::size_t i = 1; i < grid.size(); ++i) {
    if (!below(grid[i])) continue;
    double lo = grid[i - 1], hi = grid[i];
    for (int iteration = 0; iteration < 200 && hi - lo > 1e-9 * hi; ++iteration) {
      const double mid = lo > 0.0 ? std::sqrt(lo * hi) : 0.5 * hi;
      (below(mid) ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
  }
  return std::nullopt;
}

}  // namespace servotwin::core
