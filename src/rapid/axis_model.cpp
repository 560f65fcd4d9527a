// Eq. 3.3 coefficients, the Eq. 3.10 normalisation, transfer functions, poles/zeros and bandwidth.
// The time simulation lives in axis_model_simulation.cpp, the fit metrics in axis_model_metrics.cpp.
#include "servotwin/rapid/axis_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "servotwin/core/error.hpp"
#include "servotwin/core/state_space.hpp"

namespace servotwin::rapid {

namespace {

void require_finite(const Vector8& theta, const std::string& what) {
  for (int k = 0; k < kParameterCount; ++k) {
    if (!std::isfinite(theta(k))) {
      throw core::InputError(core::at_field(what), "parameter " + std::to_string(k) + " (" +
                                              std::string(kRegressorNames[static_cast<std::size_t>(k)]) +
                                              ") is not finite");
    }
  }
}

void require_finite_coefficients(const ModelCoefficients& c) {
  const std::pair<const char*, double> values[] = {{"a1", c.a1}, {"a2", c.a2}, {"a3", c.a3}, {"b0", c.b0},
                                                   {"b1", c.b1}, {"b2", c.b2}, {"d0", c.d0}, {"d1", c.d1}};
  for (const auto& [name, value] : values) {
    if (!std::isfinite(value)) throw core::InputError(core::at_field(name), "model coefficient must be finite");
  }
}

// exp(A ts) and the ZOH input vectors of z = (x, x', e_i) with inputs (w - F, x_r); see the header.
AxisModel::Kernel make_kernel(const ModelCoefficients& c, double ts) {
  core::StateSpace sys;
  sys.A = Eigen::MatrixXd::Zero(3, 3);
  sys.A << 0.0, 1.0, 0.0, -c.a2, -c.a1, c.a3, -1.0, 0.0, 0.0;
  sys.B = Eigen::MatrixXd::Zero(3, 2);
  sys.B(1, 0) = 1.0;
  sys.B(2, 1) = 1.0;
  sys.C = Eigen::MatrixXd::Zero(1, 3);
  sys.C(0, 0) = 1.0;
  sys.D = Eigen::MatrixXd::Zero(1, 2);
  AxisModel::Kernel k;
  try {
    const core::DiscreteStateSpace d = core::discretize_zoh(sys, ts);
    if (!d.A.allFinite() || !d.B.allFinite()) return k;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) k.phi[i][j] = d.A(i, j);
      k.gamma_w[i] = d.B(i, 0);
      k.gamma_r[i] = d.B(i, 1);
    }
    k.valid = true;
  } catch (const std::invalid_argument&) {
    // exp(A ts) overflows: the model grows by more than e^700 per sample; simulate() reports it.
  }
  return k;
}

}  // namespace

ModelCoefficients coefficients_from_theta(const Vector8& theta) {
  require_finite(theta, "theta");
  const double alpha2 = theta(2);
  if (alpha2 == 0.0) throw core::InputError(core::at_field("theta[2] (alpha_2)"), "alpha_2 = 1/a2 must be nonzero");
  const double a2 = 1.0 / alpha2;
  ModelCoefficients c;
  c.a2 = a2;
  c.a3 = theta(0) * a2;  // alpha_i
  c.a1 = theta(1) * a2;  // alpha_1
  c.b2 = theta(3) * a2;  // beta_0
  c.b1 = theta(4) * a2;  // beta_1
  c.b0 = theta(5) * a2;  // beta_2
  c.d0 = theta(6) * a2;  // delta+
  c.d1 = theta(7) * a2;  // delta-
  return c;
}

Vector8 theta_from_coefficients(const ModelCoefficients& c) {
  if (!std::isfinite(c.a2) || c.a2 == 0.0) {
    throw core::InputError(core::at_field("a2"), "a2 must be finite and nonzero to normalise the model (Eq. 3.10)");
  }
  const double inv = 1.0 / c.a2;
  Vector8 theta;
  theta << c.a3 * inv, c.a1 * inv, inv, c.b2 * inv, c.b1 * inv, c.b0 * inv, c.d0 * inv, c.d1 * inv;
  require_finite(theta, "coefficients");
  return theta;
}

AxisModel::AxisModel(const ModelCoefficients& coefficients, double ts) : c_(coefficients), ts_(ts) {
  require_finite_coefficients(c_);
  if (!std::isfinite(ts) || ts <= 0.0) throw core::InputError(core::at_field("ts"), "sample period must be finite and > 0");
  kernel_ = make_kernel(c_, ts_);
}

core::TransferFunction AxisModel::tracking() const {
  if (c_.a3 == 0.0) return {core::Polynomial{c_.b0, c_.b1, c_.b2}, core::Polynomial{1.0, c_.a1, c_.a2}};
  return {core::Polynomial{c_.b0, c_.b1, c_.b2, c_.a3}, core::Polynomial{1.0, c_.a1, c_.a2, c_.a3}};
}

core::TransferFunction AxisModel::disturbance() const {
  if (c_.a3 == 0.0) return {core::Polynomial{-1.0}, core::Polynomial{1.0, c_.a1, c_.a2}};
  return {core::Polynomial{-1.0, 0.0}, core::Polynomial{1.0, c_.a1, c_.a2, c_.a3}};
}

std::vector<std::complex<double>> AxisModel::tracking_response(std::span<const double> omega_rad_s) const {
  return tracking().frequency_response(omega_rad_s);
}

std::vector<std::complex<double>> AxisModel::disturbance_response(std::span<const double> omega_rad_s) const {
  return disturbance().frequency_response(omega_rad_s);
}

std::vector<core::ModalInfo> AxisModel::poles() const {
  std::vector<core::ModalInfo> out;
  for (const std::complex<double>& r : tracking().poles()) out.push_back(core::modal_info(r));
  return out;
}

std::vector<core::ModalInfo> AxisModel::zeros() const {
  std::vector<core::ModalInfo> out;
  for (const std::complex<double>& r : tracking().zeros()) out.push_back(core::modal_info(r));
  return out;
}

bool AxisModel::is_stable() const {
  const std::vector<core::ModalInfo> p = poles();
  return std::all_of(p.begin(), p.end(), [](const core::ModalInfo& m) { return m.root.real() < 0.0; });
}

double AxisModel::tracking_dc_gain() const {
  if (c_.a3 != 0.0) return 1.0;
  return c_.b2 / c_.a2;
}

double AxisModel::disturbance_dc_gain() const {
  if (c_.a3 != 0.0) return 0.0;
  return -1.0 / c_.a2;
}

double AxisModel::bandwidth_hz() const {
  const double dc = std::abs(tracking_dc_gain());
  if (!std::isfinite(dc) || dc == 0.0) return std::numeric_limits<double>::quiet_NaN();
  const core::TransferFunction g = tracking();
  const double threshold = dc * std::pow(10.0, -3.0 / 20.0);
  const double nyquist = std::numbers::pi / ts_;
  const auto below = [&](double w) { return std::abs(g.frequency_response(w)) < threshold; };

  // The grid starts three decades below the slowest pole or zero, where |G| is within ~1e-3 of DC.
  double slowest = nyquist;
  std::vector<double> grid;
  for (const std::complex<double>& r : g.poles())
    if (std::abs(r) > 0.0) slowest = std::min(slowest, std::abs(r));
  for (const std::complex<double>& r : g.zeros()) {
    const double m = std::abs(r);
    if (m > 0.0) slowest = std::min(slowest, m);
    if (m > 0.0 && m < nyquist) grid.push_back(m);  // a notch's minimum sits near |zero|
  }
  const double lowest = 1e-3 * slowest;
  const auto decades = std::log10(nyquist / lowest);
  const auto count = static_cast<std::size_t>(std::ceil(200.0 * decades)) + 2;
  const std::vector<double> log_grid = core::log_space(lowest, nyquist, count);
  grid.insert(grid.end(), log_grid.begin(), log_grid.end());
  std::sort(grid.begin(), grid.end());

  double lo = 0.0;  // |G(0)| = dc is not below the threshold
  for (const double w : grid) {
    if (!below(w)) {
      lo = w;
      continue;
    }
    double hi = w;
    // Bisection (geometric once the bracket is away from 0) to 1e-12 relative.
    for (int it = 0; it < 200 && hi - lo > 1e-12 * hi; ++it) {
      const double mid = lo > 0.0 ? std::sqrt(lo * hi) : 0.5 * hi;
      (below(mid) ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi) / (2.0 * std::numbers::pi);
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace servotwin::rapid
