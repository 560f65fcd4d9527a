#pragma once
/// \file
/// State-space models, exact zero-order-hold discretization and time simulation.

#include <Eigen/Dense>
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

/// Realization of a proper transfer function in controller canonical form, identical to
/// scipy.signal.tf2ss. Throws std::invalid_argument for an improper one.
StateSpace to_state_space(const TransferFunction& g);

/// Exact zero-order-hold discretization (matrix exponential of the augmented [[A B][0 0]] ts),
/// equivalent to scipy.signal.cont2discrete(method="zoh"). ts must be > 0.
DiscreteStateSpace discretize_zoh(const StateSpace& sys, double ts);

/// Response of a discrete system to an input sequence. `u` holds one row per sample and one column
/// per input; the result holds one row per sample and one column per output. x0 defaults to 0.
Eigen::MatrixXd simulate(const DiscreteStateSpace& sys, const Eigen::MatrixXd& u,
                         const Eigen::VectorXd& x0 = Eigen::VectorXd());

/// Response of a continuous system to a zero-order-held input sampled at ts (scipy.signal.lsim
/// with interp=False). Same shapes as `simulate`.
Eigen::MatrixXd simulate_zoh(const StateSpace& sys, const Eigen::MatrixXd& u, double ts,
                             const Eigen::VectorXd& x0 = Eigen::VectorXd());

/// Step response of a SISO transfer function at n samples t = 0, ts, ..., (n-1) ts.
std::vector<double> step_response(const TransferFunction& g, double ts, std::size_t n);

}  // namespace servotwin::core
