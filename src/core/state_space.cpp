#include "servotwin/core/state_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>
#include <utility>
#include <vector>

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

// ---- interconnection algebra -------------------------------------------------------------------

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Reciprocal condition number below which a matrix counts as singular to working precision.
constexpr double kSingularRcond = 100.0 * kEps;

void check_system(const StateSpace& sys, const char* who) { check_shapes(sys.A, sys.B, sys.C, sys.D, who); }

Eigen::MatrixXd block_diagonal(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(a.rows() + b.rows(), a.cols() + b.cols());
  m.topLeftCorner(a.rows(), a.cols()) = a;
  m.bottomRightCorner(b.rows(), b.cols()) = b;
  return m;
}

/// (I - m)^-1 for a loop gain m, or std::invalid_argument naming `who` when the loop is
/// algebraically ill-posed.
Eigen::MatrixXd loop_inverse(const Eigen::MatrixXd& m, const char* who) {
  const Eigen::MatrixXd i_minus_m = Eigen::MatrixXd::Identity(m.rows(), m.cols()) - m;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(i_minus_m);
  if (!(lu.rcond() >= kSingularRcond))
    throw std::invalid_argument(std::string(who) + ": algebraic loop (I - D1 D2 is singular: the direct feedthroughs close an ill-posed loop)");
  return lu.inverse();
}

}  // namespace

StateSpace series(const StateSpace& a, const StateSpace& b) {
  check_system(a, "series");
  check_system(b, "series");
  require(b.inputs() == a.outputs(), "series: b must have as many inputs as a has outputs");
  const Eigen::Index na = a.states(), nb = b.states();
  StateSpace s;
  s.A = block_diagonal(a.A, b.A);
  s.A.bottomLeftCorner(nb, na) = b.B * a.C;
  s.B.resize(na + nb, a.inputs());
  s.B << a.B, b.B * a.D;
  s.C.resize(b.outputs(), na + nb);
  s.C << b.D * a.C, b.C;
  s.D = b.D * a.D;
  return s;
}

StateSpace parallel(const StateSpace& a, const StateSpace& b) {
  check_system(a, "parallel");
  check_system(b, "parallel");
  require(a.inputs() == b.inputs() && a.outputs() == b.outputs(), "parallel: a and b must have the same inputs and outputs");
  StateSpace s;
  s.A = block_diagonal(a.A, b.A);
  s.B.resize(a.states() + b.states(), a.inputs());
  s.B << a.B, b.B;
  s.C.resize(a.outputs(), a.states() + b.states());
  s.C << a.C, b.C;
  s.D = a.D + b.D;
  return s;
}

StateSpace feedback(const StateSpace& g, const StateSpace& h, int sign) {
  check_system(g, "feedback");
  check_system(h, "feedback");
  require(sign == 1 || sign == -1, "feedback: sign must be +1 or -1");
  require(h.inputs() == g.outputs() && h.outputs() == g.inputs(),
          "feedback: h must map g's outputs to g's inputs (h.inputs == g.outputs, h.outputs == g.inputs)");
  const double sg = static_cast<double>(sign);
  const Eigen::Index n1 = g.states(), n2 = h.states(), m = g.inputs();
  // y = C1 x1 + D1 u, u = r + sign (C2 x2 + D2 y)  =>  y = E (C1 x1 + sign D1 C2 x2 + D1 r).
  const Eigen::MatrixXd e = loop_inverse(sg * g.D * h.D, "feedback");
  Eigen::MatrixXd cy(g.outputs(), n1 + n2);
  cy << e * g.C, sg * e * g.D * h.C;
  const Eigen::MatrixXd dy = e * g.D;
  Eigen::MatrixXd cu(m, n1 + n2);
  cu << Eigen::MatrixXd::Zero(m, n1), sg * h.C;
  cu += sg * h.D * cy;
  const Eigen::MatrixXd du = Eigen::MatrixXd::Identity(m, m) + sg * h.D * dy;
  StateSpace s;
  s.A = block_diagonal(g.A, h.A);
  s.A.topRows(n1) += g.B * cu;
  s.A.bottomRows(n2) += h.B * cy;
  s.B.resize(n1 + n2, m);
  s.B << g.B * du, h.B * dy;
  s.C = cy;
  s.D = dy;
  return s;
}

StateSpace append(const StateSpace& a, const StateSpace& b) {
  check_system(a, "append");
  check_system(b, "append");
  StateSpace s;
  s.A = block_diagonal(a.A, b.A);
  s.B = block_diagonal(a.B, b.B);
  s.C = block_diagonal(a.C, b.C);
  s.D = block_diagonal(a.D, b.D);
  return s;
}

StateSpace lft_lower(const StateSpace& p, const StateSpace& k, Eigen::Index ny, Eigen::Index nu) {
  check_system(p, "lft_lower");
  check_system(k, "lft_lower");
  require(nu >= 1 && nu < p.inputs(), "lft_lower: need 1 <= nu < P.inputs()");
  require(ny >= 1 && ny < p.outputs(), "lft_lower: need 1 <= ny < P.outputs()");
  require(k.inputs() == ny && k.outputs() == nu, "lft_lower: K must have ny inputs and nu outputs");
  const Eigen::Index n = p.states(), nk = k.states();
  const Eigen::Index m1 = p.inputs() - nu, p1 = p.outputs() - ny;
  const Eigen::MatrixXd b1 = p.B.leftCols(m1), b2 = p.B.rightCols(nu);
  const Eigen::MatrixXd c1 = p.C.topRows(p1), c2 = p.C.bottomRows(ny);
  const Eigen::MatrixXd d11 = p.D.topLeftCorner(p1, m1), d12 = p.D.topRightCorner(p1, nu);
  const Eigen::MatrixXd d21 = p.D.bottomLeftCorner(ny, m1), d22 = p.D.bottomRightCorner(ny, nu);
  // u = CK xK + DK y, y = C2 x + D21 w + D22 u  =>  u = R (DK C2 x + CK xK + DK D21 w).
  const Eigen::MatrixXd r = loop_inverse(k.D * d22, "lft_lower");
  Eigen::MatrixXd cu(nu, n + nk);
  cu << r * k.D * c2, r * k.C;
  const Eigen::MatrixXd du = r * k.D * d21;
  Eigen::MatrixXd cy(ny, n + nk);
  cy << c2, Eigen::MatrixXd::Zero(ny, nk);
  cy += d22 * cu;
  const Eigen::MatrixXd dy = d21 + d22 * du;
  StateSpace s;
  s.A = block_diagonal(p.A, k.A);
  s.A.topRows(n) += b2 * cu;
  s.A.bottomRows(nk) += k.B * cy;
  s.B.resize(n + nk, m1);
  s.B << b1 + b2 * du, k.B * dy;
  s.C.resize(p1, n + nk);
  s.C << c1, Eigen::MatrixXd::Zero(p1, nk);
  s.C += d12 * cu;
  s.D = d11 + d12 * du;
  return s;
}

// ---- DC gain, transfer functions -----------------------------------------------------------------

namespace {

using Complex = std::complex<double>;

std::vector<Complex> eigenvalues(const Eigen::MatrixXd& a, const char* who) {
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(a, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) throw std::runtime_error(std::string(who) + ": eigenvalue iteration did not converge");
  std::vector<Complex> out(static_cast<std::size_t>(a.rows()));
  for (Eigen::Index i = 0; i < a.rows(); ++i) out[static_cast<std::size_t>(i)] = solver.eigenvalues()(i);
  return out;
}

/// Monic characteristic polynomial from eigenvalues, and prod (s + |lambda_i|): the latter bounds
/// every coefficient's magnitude and so sets the rounding scale of the former.
std::pair<Polynomial, Polynomial> characteristic_polynomial(const Eigen::MatrixXd& a, const char* who) {
  const std::vector<Complex> lambda = eigenvalues(a, who);
  std::vector<Complex> moduli;
  moduli.reserve(lambda.size());
  for (const Complex& l : lambda) moduli.emplace_back(-std::abs(l), 0.0);
  return {Polynomial::from_roots(lambda), Polynomial::from_roots(moduli)};
}

}  // namespace

StateSpace balance_states(const StateSpace& sys) {
  check_system(sys, "balance_states");
  return detail::balanced(sys);
}

Eigen::MatrixXd dc_gain(const StateSpace& sys) {
  check_system(sys, "dc_gain");
  if (sys.states() == 0) return sys.D;
  const StateSpace b = detail::balanced(sys);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(b.A);
  if (!(lu.rcond() >= kSingularRcond))
    throw std::domain_error("dc_gain: A is singular (a pole at s = 0), the DC gain is not finite");
  return b.D - b.C * lu.solve(b.B);
}

TransferFunction to_transfer_function(const StateSpace& sys, Eigen::Index output, Eigen::Index input) {
  check_system(sys, "to_transfer_function");
  require(output >= 0 && output < sys.outputs(), "to_transfer_function: output index out of range");
  require(input >= 0 && input < sys.inputs(), "to_transfer_function: input index out of range");
  const double d = sys.D(output, input);
  if (sys.states() == 0) return {Polynomial{d}, Polynomial{1.0}};
  const StateSpace bal = detail::balanced(sys);
  const Eigen::VectorXd b = bal.B.col(input);
  const Eigen::RowVectorXd c = bal.C.row(output);
  const auto [den, den_scale] = characteristic_polynomial(bal.A, "to_transfer_function");
  const double bc = b.norm() * c.norm();
  if (bc == 0.0) return {d * den, den};
  const double a_norm = bal.A.norm();
  const double alpha = (a_norm > 0.0 ? a_norm : 1.0) / bc;
  const auto [shifted, shifted_scale] = characteristic_polynomial(bal.A - alpha * b * c, "to_transfer_function");
  // num_k = (shifted_k - den_k) / alpha. A difference below the rounding level of its terms carries
  // no information (a structurally zero coefficient, e.g. c b = 0 for relative degree >= 2) and
  // becomes an exact zero instead of a spurious tiny leading coefficient with a root near infinity.
  const int n = den.degree();
  const double noise_factor = 16.0 * static_cast<double>(n + 1) * kEps;
  std::vector<double> num(static_cast<std::size_t>(n) + 1, 0.0);
  for (int k = 0; k < n; ++k) {
    const double difference = (shifted.coefficient_of_power(k) - den.coefficient_of_power(k)) / alpha;
    const double noise = noise_factor * (shifted_scale.coefficient_of_power(k) + den_scale.coefficient_of_power(k)) / alpha;
    num[static_cast<std::size_t>(n - k)] = std::abs(difference) <= noise ? 0.0 : difference;
  }
  return {Polynomial(std::move(num)) + d * den, den};
}

// ---- Tustin ------------------------------------------------------------------------------------------

DiscreteStateSpace discretize_tustin(const StateSpace& sys, double ts, std::optional<double> prewarp_rad_s) {
  check_system(sys, "discretize_tustin");
  require(std::isfinite(ts) && ts > 0.0, "discretize_tustin: ts must be finite and > 0");
  double t = ts;
  if (prewarp_rad_s) {
    const double wp = *prewarp_rad_s;
    require(std::isfinite(wp) && wp > 0.0 && wp * ts < std::numbers::pi,
            "discretize_tustin: the prewarp frequency must lie in (0, pi/ts)");
    t = 2.0 * std::tan(0.5 * wp * ts) / wp;
  }
  const Eigen::Index n = sys.states();
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(n, n);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(identity - 0.5 * t * sys.A);
  if (n > 0 && !(lu.rcond() >= kSingularRcond))
    throw std::domain_error("discretize_tustin: I - (T/2) A is singular (A has an eigenvalue at 2/T)");
  DiscreteStateSpace d;
  d.ts = ts;
  if (n == 0) {
    d.A = sys.A;
    d.B = sys.B;
    d.C = sys.C;
    d.D = sys.D;
    return d;
  }
  d.A = lu.solve(identity + 0.5 * t * sys.A);
  d.B = lu.solve(sys.B * t);
  // C M^-1 = (M^-T C^T)^T.
  const Eigen::MatrixXd m_transposed = (identity - 0.5 * t * sys.A).transpose();
  d.C = Eigen::PartialPivLU<Eigen::MatrixXd>(m_transposed).solve(sys.C.transpose()).transpose();
  d.D = sys.D + 0.5 * sys.C * d.B;
  return d;
}

// ---- frequency responses -----------------------------------------------------------------------------

FrequencyResponseEvaluator::FrequencyResponseEvaluator(const StateSpace& sys) {
  check_system(sys, "FrequencyResponseEvaluator");
  init(sys.A, sys.B, sys.C, sys.D);
}

FrequencyResponseEvaluator::FrequencyResponseEvaluator(const DiscreteStateSpace& sys) {
  check_shapes(sys.A, sys.B, sys.C, sys.D, "FrequencyResponseEvaluator");
  init(sys.A, sys.B, sys.C, sys.D);
}

void FrequencyResponseEvaluator::init(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c,
                                      const Eigen::MatrixXd& d) {
  const Eigen::Index n = a.rows();
  d_ = d.cast<Complex>();
  if (n == 0) {
    h_.resize(0, 0);
    b_.resize(0, b.cols());
    c_.resize(c.rows(), 0);
    return;
  }
  Eigen::MatrixXd ab = a;
  const Eigen::VectorXd t = detail::balance(ab);
  const Eigen::HessenbergDecomposition<Eigen::MatrixXd> hessenberg(ab);
  const Eigen::MatrixXd q = hessenberg.matrixQ();
  h_ = Eigen::MatrixXd(hessenberg.matrixH()).cast<Complex>();
  b_ = (q.transpose() * (t.cwiseInverse().asDiagonal() * b)).cast<Complex>();
  c_ = ((c * t.asDiagonal()) * q).cast<Complex>();
  work_.resize(n, n);
  x_.resize(n, b.cols());
}

void FrequencyResponseEvaluator::evaluate(std::complex<double> s, Eigen::MatrixXcd& out) {
  const Eigen::Index n = h_.rows(), m = b_.cols();
  out.resize(c_.rows(), m);
  if (n == 0) {
    out = d_;
    return;
  }
  // (sI - H) X = B by Gaussian elimination; H is upper Hessenberg, so only rows k and k+1 take part
  // in step k and partial pivoting is a choice between those two (stable like LU with partial
  // pivoting, at O(n^2) cost).
  work_ = -h_;
  work_.diagonal().array() += s;
  x_ = b_;
  for (Eigen::Index k = 0; k + 1 < n; ++k) {
    if (std::abs(work_(k + 1, k)) > std::abs(work_(k, k))) {
      for (Eigen::Index j = k; j < n; ++j) std::swap(work_(k, j), work_(k + 1, j));
      for (Eigen::Index j = 0; j < m; ++j) std::swap(x_(k, j), x_(k + 1, j));
    }
    if (work_(k + 1, k) == Complex(0.0)) continue;
    const Complex l = work_(k + 1, k) / work_(k, k);
    for (Eigen::Index j = k + 1; j < n; ++j) work_(k + 1, j) -= l * work_(k, j);
    for (Eigen::Index j = 0; j < m; ++j) x_(k + 1, j) -= l * x_(k, j);
  }
  for (Eigen::Index k = n - 1; k >= 0; --k) {
    for (Eigen::Index j = 0; j < m; ++j) {
      Complex acc = x_(k, j);
      for (Eigen::Index i = k + 1; i < n; ++i) acc -= work_(k, i) * x_(i, j);
      x_(k, j) = acc / work_(k, k);
    }
  }
  out.noalias() = c_.lazyProduct(x_);
  out += d_;
}

Eigen::MatrixXcd FrequencyResponseEvaluator::operator()(std::complex<double> s) {
  Eigen::MatrixXcd out;
  evaluate(s, out);
  return out;
}

Eigen::MatrixXcd frequency_response(const StateSpace& sys, double omega_rad_s) {
  require(std::isfinite(omega_rad_s), "frequency_response: omega must be finite");
  FrequencyResponseEvaluator evaluator(sys);
  return evaluator(Complex(0.0, omega_rad_s));
}

std::complex<double> frequency_response(const StateSpace& sys, double omega_rad_s, Eigen::Index output, Eigen::Index input) {
  require(output >= 0 && output < sys.outputs(), "frequency_response: output index out of range");
  require(input >= 0 && input < sys.inputs(), "frequency_response: input index out of range");
  StateSpace channel{sys.A, sys.B.col(input), sys.C.row(output), sys.D.block(output, input, 1, 1)};
  return frequency_response(channel, omega_rad_s)(0, 0);
}

Eigen::MatrixXcd frequency_response(const DiscreteStateSpace& sys, double omega_rad_s) {
  require(std::isfinite(omega_rad_s), "frequency_response: omega must be finite");
  require(std::isfinite(sys.ts) && sys.ts > 0.0, "frequency_response: ts must be finite and > 0");
  FrequencyResponseEvaluator evaluator(sys);
  return evaluator(std::polar(1.0, omega_rad_s * sys.ts));
}

}  // namespace servotwin::core
