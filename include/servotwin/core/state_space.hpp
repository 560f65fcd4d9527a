#pragma once
/// \file
/// State-space models, exact zero-order-hold discretization and time simulation.

#include <Eigen/Dense>
#include <cstddef>
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

}  // namespace servotwin::core
