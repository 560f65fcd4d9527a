#include "servotwin/core/state_space.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "balance.hpp"

namespace servotwin::core {

namespace {

void require(bool condition, const char* message) {
  if (!condition) throw std::invalid_argument(message);
}

template <typename Matrix>
bool all_finite(const Matrix& m) {
  return m.size() == 0 || m.allFinite();
}

void check_shapes(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c,
                  const Eigen::MatrixXd& d, const char* who) {
  const std::string prefix(who);
  if (a.rows() != a.cols()) throw std::invalid_argument(prefix + ": A must be square");
  if (b.rows() != a.rows()) throw std::invalid_argument(prefix + ": B must have as many rows as A");
  if (c.cols() != a.rows()) throw std::invalid_argument(prefix + ": C must have as many columns as A");
  if (d.rows() != c.rows() || d.cols() != b.cols())
    throw std::invalid_argument(prefix + ": D must be outputs x inputs");
  if (!all_finite(a) || !all_finite(b) || !all_finite(c) || !all_finite(d))
    throw std::invalid_argument(prefix + ": matrices must be finite");
}

}  // namespace

StateSpace to_state_space(const TransferFunction& g) {
  require(g.is_proper(), "to_state_space: the transfer function is improper (deg num > deg den)");
  const TransferFunction monic = g.normalized();
  const std::span<const double> den = monic.den().coefficients();
  const auto k = static_cast<Eigen::Index>(den.size());  // states + 1
  // Numerator padded to the denominator's length (a zero numerator is [0 ... 0]).
  Eigen::VectorXd num = Eigen::VectorXd::Zero(k);
  const std::span<const double> nc = monic.num().coefficients();
  for (std::size_t i = 0; i < nc.size(); ++i) num(k - static_cast<Eigen::Index>(nc.size()) + static_cast<Eigen::Index>(i)) = nc[i];

  StateSpace ss;
  if (k == 1) {  // static gain: scipy's one dummy state
    ss.A = Eigen::MatrixXd::Zero(1, 1);
    ss.B = Eigen::MatrixXd::Zero(1, 1);
    ss.C = Eigen::MatrixXd::Zero(1, 1);
    ss.D = Eigen::MatrixXd::Constant(1, 1, num(0));
    return ss;
  }
  const Eigen::Index n = k - 1;
  ss.A = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) ss.A(0, j) = -den[static_cast<std::size_t>(j + 1)];
  for (Eigen::Index i = 1; i < n; ++i) ss.A(i, i - 1) = 1.0;
  ss.B = Eigen::MatrixXd::Zero(n, 1);
  ss.B(0, 0) = 1.0;
  ss.C.resize(1, n);
  for (Eigen::Index j = 0; j < n; ++j) ss.C(0, j) = num(j + 1) - num(0) * den[static_cast<std::size_t>(j + 1)];
  ss.D = Eigen::MatrixXd::Constant(1, 1, num(0));
  return ss;
}

DiscreteStateSpace discretize_zoh(const StateSpace& sys, double ts) {
  check_shapes(sys.A, sys.B, sys.C, sys.D, "discretize_zoh");
  require(std::isfinite(ts) && ts > 0.0, "discretize_zoh: ts must be finite and > 0");
  const Eigen::Index n = sys.states();
  const Eigen::Index m = sys.inputs();
  // exp([[A B][0 0]] ts) = [[Ad Bd][0 I]] (Van Loan); Eigen's exp is scaling and squaring with a
  // degree-13 Pade approximant (Higham 2005), the same family as scipy.linalg.expm.
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(n + m, n + m);
  augmented.topLeftCorner(n, n) = sys.A * ts;
  augmented.topRightCorner(n, m) = sys.B * ts;
  // Mechanical models mix states of very different scale (positions and velocities: entries 1 and
  // k/J ~ 1e5 in one matrix). exp(D M D^-1) = D exp(M) D^-1, and balancing with powers of two
  // lowers the norm, hence the number of squarings and their error growth, without rounding.
  const Eigen::VectorXd scaling = detail::balance(augmented);
  Eigen::MatrixXd e = augmented.exp();
  e = scaling.asDiagonal() * e * scaling.cwiseInverse().asDiagonal();
  require(e.allFinite(), "discretize_zoh: the discretized system overflows (unstable mode far beyond one sample)");
  DiscreteStateSpace d;
  d.A = e.topLeftCorner(n, n);
  d.B = e.topRightCorner(n, m);
  d.C = sys.C;
  d.D = sys.D;
  d.ts = ts;
  return d;
}

DiscreteSimulator::DiscreteSimulator(const DiscreteStateSpace& sys)
    : n_(sys.A.rows()), m_(sys.B.cols()), p_(sys.C.rows()) {
  check_shapes(sys.A, sys.B, sys.C, sys.D, "DiscreteSimulator");
  ab_.resize(n_, n_ + m_);
  ab_ << sys.A, sys.B;
  cd_.resize(p_, n_ + m_);
  cd_ << sys.C, sys.D;
  x_ = Eigen::VectorXd::Zero(n_);
  xu_ = Eigen::VectorXd::Zero(n_ + m_);
  y_ = Eigen::VectorXd::Zero(p_);
}

void DiscreteSimulator::set_state(const Eigen::VectorXd& x) {
  require(x.size() == n_, "DiscreteSimulator::set_state: state size differs from the system's");
  x_ = x;
}

void DiscreteSimulator::step(std::span<const double> u, std::span<double> y) noexcept {
  const Eigen::Index width = n_ + m_;
  double* xu = xu_.data();
  for (Eigen::Index i = 0; i < n_; ++i) xu[i] = x_[i];
  for (Eigen::Index j = 0; j < m_; ++j) xu[n_ + j] = u[static_cast<std::size_t>(j)];
  // Plain loops: for the handful of states of an axis model they beat a generic product call.
  for (Eigen::Index r = 0; r < p_; ++r) {
    const double* row = cd_.data() + r * width;
    double acc = 0.0;
    for (Eigen::Index j = 0; j < width; ++j) acc += row[j] * xu[j];
    y[static_cast<std::size_t>(r)] = acc;
  }
  double* x = x_.data();
  for (Eigen::Index r = 0; r < n_; ++r) {
    const double* row = ab_.data() + r * width;
    double acc = 0.0;
    for (Eigen::Index j = 0; j < width; ++j) acc += row[j] * xu[j];
    x[r] = acc;
  }
}

double DiscreteSimulator::step(double u) noexcept {
  step(std::span<const double>(&u, 1), std::span<double>(y_.data(), static_cast<std::size_t>(p_)));
  return p_ > 0 ? y_[0] : 0.0;
}

Eigen::MatrixXd simulate(const DiscreteStateSpace& sys, const Eigen::MatrixXd& u, const Eigen::VectorXd& x0) {
  DiscreteSimulator simulator(sys);
  require(u.cols() == simulator.inputs(), "simulate: u must have one column per system input");
  if (x0.size() != 0) simulator.set_state(x0);
  const Eigen::Index samples = u.rows();
  const Eigen::Index m = simulator.inputs();
  const Eigen::Index p = simulator.outputs();
  // Samples are gathered into small contiguous buffers rather than copying u and y to row-major
  // layouts: only the result itself is allocated at the size of the signal.
  Eigen::MatrixXd y(samples, p);
  Eigen::VectorXd uk(m);
  Eigen::VectorXd yk(p);
  const std::span<const double> u_span(uk.data(), static_cast<std::size_t>(m));
  const std::span<double> y_span(yk.data(), static_cast<std::size_t>(p));
  for (Eigen::Index k = 0; k < samples; ++k) {
    for (Eigen::Index j = 0; j < m; ++j) uk[j] = u(k, j);
    simulator.step(u_span, y_span);
    for (Eigen::Index r = 0; r < p; ++r) y(k, r) = yk[r];
  }
  return y;
}

Eigen::MatrixXd simulate_zoh(const StateSpace& sys, const Eigen::MatrixXd& u, double ts, const Eigen::VectorXd& x0) {
  return simulate(discretize_zoh(sys, ts), u, x0);
}

std::vector<double> step_response(const TransferFunction& g, double ts, std::size_t n) {
  const DiscreteStateSpace d = discretize_zoh(to_state_space(g), ts);
  DiscreteSimulator simulator(d);
  std::vector<double> y(n);
  for (double& v : y) v = simulator.step(1.0);
  return y;
}

}  // namespace servotwin::core
