#pragma once
/// \file
/// State-space models, exact zero-order-hold and Tustin discretization, time simulation,
/// interconnection algebra (series, parallel, feedback, append, lower LFT), DC gain, frequency
/// responses and SISO transfer-function extraction.

#include <Eigen/Dense>
#include <complex>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "servotwin/core/transfer_function.hpp"

namespace servotwin::core {

/// Continuous-time x' = A x + B u, y = C x + D u.
struct StateSpace {
  Eigen::MatrixXd A, B, C, D;
  [[nodiscard]] Eigen::Index states() const noexcept { return A.rows(); }
  [[nodiscard]] Eigen::Index inputs() const noexcept { return B.cols(); }
  [[nodiscard]] Eigen::Index outputs() const noexcept { return C.rows(); }
};

/// Discrete-time x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k] with sample period ts [s].
struct DiscreteStateSpace {
  Eigen::MatrixXd A, B, C, D;
  double ts = 0.0;
  [[nodiscard]] Eigen::Index states() const noexcept { return A.rows(); }
};

// Errors: the functions below are numerical kernels called with values that readers have already
// validated, so inconsistent arguments (mismatched matrix shapes, ts <= 0, non-finite matrices,
// improper transfer functions) are programming errors and throw std::invalid_argument. Readers
// of user files check the same conditions first and report them as core::InputError.

/// Realization of a proper transfer function in controller canonical form, identical to
/// scipy.signal.tf2ss (after normalising the denominator to leading coefficient 1):
///   A = [-a1 -a2 ... -an; I 0], B = e1, C = [b1 - b0 a1, ..., bn - b0 an], D = b0.
/// Like scipy, a static gain (denominator degree 0) gets one dummy state with A = B = C = 0.
/// Throws std::invalid_argument for an improper transfer function.
StateSpace to_state_space(const TransferFunction& g);

/// Exact zero-order-hold discretization (matrix exponential of the augmented [[A B][0 0]] ts,
/// balanced by powers of two before Eigen's scaling-and-squaring Pade exponential), equivalent to
/// scipy.signal.cont2discrete(method="zoh"). ts must be finite and > 0; a discretization that
/// overflows (an unstable mode with Re(lambda) ts > ~700) throws std::invalid_argument.
DiscreteStateSpace discretize_zoh(const StateSpace& sys, double ts);

/// Sample-by-sample evaluation of a discrete system, allocation-free and exception-free after
/// construction: the virtual machine's and the simulations' inner loop.
class DiscreteSimulator {
 public:
  /// Throws std::invalid_argument when the matrix shapes are inconsistent.
  explicit DiscreteSimulator(const DiscreteStateSpace& sys);

  /// Sets the state (size must equal states(); checked with an exception, not on the hot path).
  void set_state(const Eigen::VectorXd& x);
  void reset() noexcept { x_.setZero(); }
  [[nodiscard]] const Eigen::VectorXd& state() const noexcept { return x_; }

  /// One sample: writes y[k] = C x[k] + D u[k] (outputs() values) and advances x to
  /// x[k+1] = A x[k] + B u[k]. `u` must hold inputs() values and `y` outputs() values (not
  /// checked: this is the hot path).
  void step(std::span<const double> u, std::span<double> y) noexcept;
  /// Single-input single-output convenience of `step` (first output for several outputs).
  double step(double u) noexcept;

  [[nodiscard]] Eigen::Index states() const noexcept { return n_; }
  [[nodiscard]] Eigen::Index inputs() const noexcept { return m_; }
  [[nodiscard]] Eigen::Index outputs() const noexcept { return p_; }

 private:
  Eigen::Index n_ = 0, m_ = 0, p_ = 0;
  // Row-major copies: each output and next-state entry is one contiguous dot product.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> ab_;  // [A B]
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> cd_;  // [C D]
  Eigen::VectorXd x_;
  Eigen::VectorXd xu_;  // scratch [x; u]
  Eigen::VectorXd y_;   // scratch output of the SISO overload
};

/// Response of a discrete system to an input sequence (scipy.signal.dlsim). `u` holds one row per
/// sample and one column per input; the result holds one row per sample and one column per
/// output: y[k] = C x[k] + D u[k], x[k+1] = A x[k] + B u[k]. x0 defaults to 0.
Eigen::MatrixXd simulate(const DiscreteStateSpace& sys, const Eigen::MatrixXd& u,
                         const Eigen::VectorXd& x0 = Eigen::VectorXd());

/// Response of a continuous system to a zero-order-held input sampled at ts (scipy.signal.lsim
/// with interp=False and T = 0, ts, 2 ts, ...). Same shapes as `simulate`.
Eigen::MatrixXd simulate_zoh(const StateSpace& sys, const Eigen::MatrixXd& u, double ts,
                             const Eigen::VectorXd& x0 = Eigen::VectorXd());

/// Step response of a SISO transfer function at n samples t = 0, ts, ..., (n-1) ts (exact: a
/// step is held constant between samples, so the zero-order-hold model is exact at the samples;
/// equals scipy.signal.dstep of cont2discrete(tf, ts, "zoh")).
std::vector<double> step_response(const TransferFunction& g, double ts, std::size_t n);

// ---- interconnection algebra -------------------------------------------------------------------
//
// Errors, in addition to the shape and finiteness checks above (std::invalid_argument): an
// interconnection whose direct feedthrough makes the loop algebraically ill-posed (I - D1 D2
// singular to working precision: reciprocal condition number below 100 eps) throws
// std::invalid_argument("... algebraic loop ..."). A quantity that does not exist for a well-formed
// system (the DC gain with a pole at s = 0, the Tustin map with a pole at s = 2/ts) throws
// std::domain_error. State order of every result: the first argument's states, then the second's.
// Zero-state systems (A 0 x 0) are accepted everywhere.

/// Cascade y = b(a(u)): a's outputs feed b's inputs (b.inputs() == a.outputs()); transfer matrix
/// Gb Ga. States [xa; xb]: A = [[Aa, 0], [Bb Ca, Ab]], B = [Ba; Bb Da], C = [Db Ca, Cb], D = Db Da.
StateSpace series(const StateSpace& a, const StateSpace& b);

/// Sum y = a(u) + b(u) (same numbers of inputs and outputs); transfer matrix Ga + Gb.
StateSpace parallel(const StateSpace& a, const StateSpace& b);

/// Closed loop of forward path g (m inputs, p outputs) and feedback path h (p inputs, m outputs):
/// u = r + sign h(y), y = g(u); transfer matrix (I - sign Gg Gh)^-1 Gg from r to y. sign = -1
/// (default) is negative feedback; anything but +-1 throws std::invalid_argument, and so does a
/// singular I - sign Dg Dh ("algebraic loop").
StateSpace feedback(const StateSpace& g, const StateSpace& h, int sign = -1);

/// Block-diagonal stacking: inputs [ua; ub], outputs [ya; yb], transfer matrix diag(Ga, Gb).
StateSpace append(const StateSpace& a, const StateSpace& b);

/// Lower linear fractional transformation F_l(P, K): P's inputs are [w; u] (u = the last nu),
/// its outputs [z; y] (y = the last ny); K maps y (ny inputs) to u (nu outputs). The result maps w
/// to z: P11 + P12 K (I - P22 K)^-1 P21. Needs 1 <= nu < P.inputs(), 1 <= ny < P.outputs()
/// (at least one exogenous input and output remain); the loop is well posed iff I - D22 DK is
/// invertible, else std::invalid_argument ("algebraic loop").
StateSpace lft_lower(const StateSpace& p, const StateSpace& k, Eigen::Index ny, Eigen::Index nu);

/// The same system in balanced state coordinates: a diagonal similarity by powers of two (exact in
/// floating point) that gives A's rows and columns comparable norms (A_b = T^-1 A T, B_b = T^-1 B,
/// C_b = C T; the transfer matrix is unchanged). For realizations whose entries span many decades
/// (synthesized controllers) before they are discretized or written out.
StateSpace balance_states(const StateSpace& sys);

/// Static gain G(0) = D - C A^-1 B (outputs x inputs), computed on the balanced A. Throws
/// std::domain_error when A is singular to working precision (a pole at s = 0: the gain is
/// infinite in the channels that see the integrator and undefined as a matrix); use
/// to_transfer_function(...).dc_gain() for a channel whose integrator cancels or to get +-inf.
Eigen::MatrixXd dc_gain(const StateSpace& sys);

/// The SISO channel from input `input` to output `output` (0-based) as a transfer function of the
/// full order n = states(): den(s) = det(sI - A) (monic), num(s) = c (adj(sI - A)) b + d den(s).
/// No pole-zero cancellation (like scipy.signal.ss2tf, which it matches). The numerator uses the
/// rank-one determinant identity det(sI - A + alpha b c) = den(s) (1 + alpha c (sI - A)^-1 b):
///   num(s) = (det(sI - A + alpha b c) - den(s)) / alpha + d den(s),
/// with both characteristic polynomials built from eigenvalues (Polynomial::from_roots) of the
/// balanced A, and alpha chosen so that alpha |b| |c| ~ |A| (the identity is exact for every alpha;
/// this one minimises the cancellation in the subtraction). A numerator coefficient whose
/// difference is below the rounding level of its two terms (16 (n+1) eps times the coefficient of
/// prod (s + |lambda_i|) of both polynomials) is set to exactly 0, so structural zeros (relative
/// degree >= 2) give the true numerator degree where scipy leaves ~1e-13 leading coefficients.
/// A zero-state system gives d / 1. Throws std::invalid_argument for indices out of range.
TransferFunction to_transfer_function(const StateSpace& sys, Eigen::Index output, Eigen::Index input);

/// Tustin (bilinear) discretization, identical to scipy.signal.cont2discrete(method="bilinear"):
/// with T = ts and M = I - (T/2) A,
///   Ad = M^-1 (I + (T/2) A), Bd = M^-1 B T, Cd = C M^-1, Dd = D + (T/2) C M^-1 B,
/// i.e. s -> (2/T) (z - 1)/(z + 1). With a prewarp frequency wp (0 < wp < pi/ts, rad/s) the map
/// is s -> (wp / tan(wp ts/2)) (z - 1)/(z + 1), which is the formula above with the effective
/// period T = 2 tan(wp ts/2)/wp in place of ts (the result's ts is still ts): the discrete
/// response at z = exp(j wp ts) equals the continuous one at s = j wp exactly. Throws
/// std::invalid_argument for ts <= 0, non-finite data or wp outside (0, pi/ts), std::domain_error
/// when M is singular (A has an eigenvalue at 2/T).
DiscreteStateSpace discretize_tustin(const StateSpace& sys, double ts, std::optional<double> prewarp_rad_s = std::nullopt);

/// Repeated evaluation of C (sI - A)^-1 B + D (Laub 1981): A is balanced and reduced once to
/// upper Hessenberg form H = Q^T A Q, so each point costs one O(n^2 + n m) elimination with
/// adjacent-row partial pivoting on sI - H instead of an O(n^3) LU. The evaluator keeps its scratch
/// space between points, so it must not be shared between threads.
class FrequencyResponseEvaluator {
 public:
  /// Throws std::invalid_argument for inconsistent shapes or non-finite matrices.
  explicit FrequencyResponseEvaluator(const StateSpace& sys);
  /// Discrete system: evaluation points are z (G(z) = C (zI - A)^-1 B + D; on the unit circle
  /// z = exp(j omega ts)).
  explicit FrequencyResponseEvaluator(const DiscreteStateSpace& sys);

  /// G(s) at a complex point into `out` (resized to outputs x inputs if needed). At a pole the
  /// result is infinite or NaN.
  void evaluate(std::complex<double> s, Eigen::MatrixXcd& out);
  /// G(s) at a complex point.
  [[nodiscard]] Eigen::MatrixXcd operator()(std::complex<double> s);

  [[nodiscard]] Eigen::Index states() const noexcept { return h_.rows(); }
  [[nodiscard]] Eigen::Index inputs() const noexcept { return b_.cols(); }
  [[nodiscard]] Eigen::Index outputs() const noexcept { return c_.rows(); }

 private:
  void init(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const Eigen::MatrixXd& c, const Eigen::MatrixXd& d);
  Eigen::MatrixXcd h_, b_, c_, d_;  // Hessenberg form, transformed B and C, D (complex copies)
  Eigen::MatrixXcd work_;           // (sI - H) during elimination
  Eigen::MatrixXcd x_;              // right-hand sides, then (sI - H)^-1 B
};

/// G(j omega) of a continuous system (outputs x inputs); omega in rad/s, finite.
Eigen::MatrixXcd frequency_response(const StateSpace& sys, double omega_rad_s);
/// One channel G_out,in(j omega) (0-based indices, checked).
std::complex<double> frequency_response(const StateSpace& sys, double omega_rad_s, Eigen::Index output, Eigen::Index input);
/// G(exp(j omega ts)) of a discrete system (outputs x inputs).
Eigen::MatrixXcd frequency_response(const DiscreteStateSpace& sys, double omega_rad_s);

}  // namespace servotwin::core
