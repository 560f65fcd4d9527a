#include "servotwin/machine/pole_placement.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/machine/rigid_axis.hpp"

namespace servotwin::machine {

namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

double max_abs(const MatrixXd& m) { return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff(); }

MatrixXd riccati_rhs(const MatrixXd& A, const MatrixXd& C, const MatrixXd& Q, const MatrixXd& R, const MatrixXd& P) {
  const MatrixXd apc = A * P * C.transpose();
  const MatrixXd s = C * P * C.transpose() + R;
  return A * P * A.transpose() - apc * s.ldlt().solve(apc.transpose()) + Q;
}

// Monic real polynomial (descending) with the given roots (conjugate pairs for complex roots).
std::vector<double> monic_from_roots(const std::vector<std::complex<double>>& roots) {
  std::vector<std::complex<double>> c{1.0};
  for (const auto& r : roots) {
    std::vector<std::complex<double>> next(c.size() + 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i] += c[i];
      next[i + 1] -= r * c[i];
    }
    c = std::move(next);
  }
  std::vector<double> out(c.size());
  std::transform(c.begin(), c.end(), out.begin(), [](const std::complex<double>& v) { return v.real(); });
  return out;
}

std::vector<std::complex<double>> eigenvalues(const MatrixXd& m) {
  const Eigen::EigenSolver<MatrixXd> solver(m, false);
  std::vector<std::complex<double>> out;
  for (Index i = 0; i < m.rows(); ++i) out.push_back(solver.eigenvalues()(i));
  std::sort(out.begin(), out.end(), [](auto a, auto b) {
    return std::abs(a) != std::abs(b) ? std::abs(a) > std::abs(b) : a.imag() > b.imag();
  });
  return out;
}

// Ackermann's formula L = e_n' Ctrb^-1 alpha(Phi) for a single-input pair.
Eigen::RowVectorXd ackermann(const MatrixXd& phi, const VectorXd& gamma, const std::vector<double>& alpha) {
  const Index n = phi.rows();
  MatrixXd ctrb(n, n);
  VectorXd col = gamma;
  for (Index j = 0; j < n; ++j) {
    ctrb.col(j) = col;
    col = phi * col;
  }
  MatrixXd poly = MatrixXd::Zero(n, n);  // alpha(Phi) by Horner
  for (double c : alpha) poly = poly * phi + c * MatrixXd::Identity(n, n);
  VectorXd en = VectorXd::Zero(n);
  en(n - 1) = 1.0;
  const VectorXd t = ctrb.transpose().colPivHouseholderQr().solve(en);
  return t.transpose() * poly;
}

}  // namespace

RiccatiSolution solve_filter_riccati(const MatrixXd& A, const MatrixXd& C, const MatrixXd& Q, const MatrixXd& R) {
  // Structure-preserving doubling on the dual control-form equation
  //   X = Ah' X (I + G X)^-1 Ah + Q,  Ah = A', G = C' R^-1 C:
  // after k iterations H_k equals 2^k steps of the Riccati recursion started from P = Q.
  const Index n = A.rows();
  const MatrixXd identity = MatrixXd::Identity(n, n);
  MatrixXd a = A.transpose();
  MatrixXd g = C.transpose() * R.ldlt().solve(C);
  MatrixXd h = Q;
  RiccatiSolution out;
  constexpr int kMaxIterations = 100;
  bool converged = false;
  for (int it = 1; it <= kMaxIterations && !converged; ++it) {
    const Eigen::PartialPivLU<MatrixXd> w(identity + g * h);
    const MatrixXd wa = w.solve(a);
    const MatrixXd wg = w.solve(g);
    const MatrixXd h_next = h + a.transpose() * h * wa;
    g = g + a * wg * a.transpose();
    a = a * wa;
    const double change = max_abs(h_next - h);
    h = 0.5 * (h_next + h_next.transpose());
    g = 0.5 * (g + g.transpose());
    out.iterations = it;
    converged = change <= 1e-14 * std::max(1.0, max_abs(h));
  }
  out.P = h;
  out.residual = max_abs(riccati_rhs(A, C, Q, R, h) - h) / std::max(1.0, max_abs(h));
  if (!converged || !h.allFinite() || out.residual > 1e-9)
    throw core::InputError("Kalman filter design: the Riccati recursion did not converge (residual " +
                           std::to_string(out.residual) +
                           "); expected a detectable plant and positive noise intensities");
  return out;
}

PolePlacementDesign design_pole_placement(const RigidPlant& plant, const PolePlacementController& controller,
                                          double ts, int delay_samples) {
  PolePlacementDesign d;
  d.delay = delay_samples;
  const double a = plant.damping / plant.inertia;
  const double kj = plant.gain / plant.inertia;
  const double e = std::exp(-a * ts);
  const double p1 = RigidAxisDynamics::phi1(a, ts);
  const double p2 = RigidAxisDynamics::phi2(a, ts);
  const Index n = 2 + delay_samples;

  // ---- plant model xi = [x, v, u(k-1)] ----
  d.phi = MatrixXd::Zero(n, n);
  d.phi(0, 0) = 1.0;
  d.phi(0, 1) = p1;
  d.phi(1, 1) = e;
  d.gamma = VectorXd::Zero(n);
  if (delay_samples == 0) {
    d.gamma << kj * p2, kj * p1;
  } else {
    d.phi(0, 2) = kj * p2;
    d.phi(1, 2) = kj * p1;
    d.gamma(2) = 1.0;
  }
  d.gamma_d = VectorXd::Zero(n);
  d.gamma_d(0) = p2;
  d.gamma_d(1) = p1;

  // Scaling to position units (x, v ts, u K/J ts^2): the matrices become O(1) whatever the units.
  const double su = kj * ts * ts;
  VectorXd scale(n);
  scale(0) = 1.0;
  scale(1) = ts;
  if (delay_samples == 1) scale(2) = su;

  // ---- state feedback ----
  const double wn = 2.0 * std::numbers::pi * controller.wn_hz;
  const double zeta = controller.zeta;
  std::vector<std::complex<double>> s_poles;
  if (zeta < 1.0) {
    const double wd = wn * std::sqrt(1.0 - zeta * zeta);
    s_poles = {{-zeta * wn, wd}, {-zeta * wn, -wd}};
  } else {
    const double r = wn * std::sqrt(zeta * zeta - 1.0);
    s_poles = {{-zeta * wn + r, 0.0}, {-zeta * wn - r, 0.0}};
  }
  std::vector<std::complex<double>> z_poles;
  for (const auto& s : s_poles) z_poles.push_back(std::exp(s * ts));
  for (int i = 0; i < delay_samples; ++i) z_poles.emplace_back(0.0, 0.0);
  d.closed_loop_den = monic_from_roots(z_poles);

  const MatrixXd phi_s = scale.asDiagonal() * d.phi * scale.cwiseInverse().asDiagonal();
  const VectorXd gamma_s = scale.cwiseProduct(d.gamma) / su;
  const Eigen::RowVectorXd l_s = ackermann(phi_s, gamma_s, d.closed_loop_den);
  d.feedback = l_s.cwiseProduct(scale.transpose()) / su;
  const MatrixXd phi_cl = d.phi - d.gamma * d.feedback;
  d.controller_poles = eigenvalues(phi_cl);
  const VectorXd dc = (MatrixXd::Identity(n, n) - phi_cl).partialPivLu().solve(d.gamma);
  d.reference_gain = 1.0 / dc(0);
  d.disturbance_gain = plant.inertia / plant.gain;

  // ---- Kalman filter on X = [xi, d] ----
  const Index na = n + 1;
  d.phi_a = MatrixXd::Zero(na, na);
  d.phi_a.topLeftCorner(n, n) = d.phi;
  d.phi_a.topRightCorner(n, 1) = -d.gamma_d;
  d.phi_a(n, n) = 1.0;
  d.gamma_a = VectorXd::Zero(na);
  d.gamma_a.head(n) = d.gamma;
  VectorXd scale_a(na);
  scale_a.head(n) = scale;
  scale_a(n) = ts * ts;
  const MatrixXd phi_as = scale_a.asDiagonal() * d.phi_a * scale_a.cwiseInverse().asDiagonal();
  MatrixXd c = MatrixXd::Zero(1, na);
  c(0, 0) = 1.0;
  MatrixXd q = MatrixXd::Zero(na, na);
  q(n, n) = controller.kalman_process_noise * ts * std::pow(ts, 4);  // var of d ts^2 per sample
  const MatrixXd r = MatrixXd::Constant(1, 1, controller.kalman_measurement_noise);
  const RiccatiSolution riccati = solve_filter_riccati(phi_as, c, q, r);
  d.riccati_iterations = riccati.iterations;
  const VectorXd m_s = riccati.P.col(0) / (riccati.P(0, 0) + r(0, 0));
  d.kalman_gain = m_s.cwiseQuotient(scale_a);
  d.covariance = scale_a.cwiseInverse().asDiagonal() * riccati.P * scale_a.cwiseInverse().asDiagonal();
  d.observer_poles = eigenvalues(d.phi_a * (MatrixXd::Identity(na, na) - d.kalman_gain * c));

  // ---- plant zero and ZPETC ----
  d.plant_numerator_gain = kj * p2;
  d.plant_zero = -(p1 * p1 - e * p2) / p2;
  d.zpetc = controller.zpetc;
  if (d.zpetc) {
    d.preview = static_cast<int>(n);
    const double z1 = d.plant_zero;
    const double b_plus = d.reference_gain * d.plant_numerator_gain;
    const double g = 1.0 / (b_plus * (1.0 - z1) * (1.0 - z1));
    // A(z) (1 - z1 z), descending: convolve with [-z1, 1].
    const auto& A = d.closed_loop_den;
    d.zpetc_taps.assign(A.size() + 1, 0.0);
    for (std::size_t i = 0; i < A.size(); ++i) {
      d.zpetc_taps[i] += -z1 * A[i] * g;
      d.zpetc_taps[i + 1] += A[i] * g;
    }
  }
  return d;
}

}  // namespace servotwin::machine
