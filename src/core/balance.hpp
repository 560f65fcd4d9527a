#pragma once
// Internal to servotwin_core: diagonal balancing shared by the root finder, the matrix
// exponential, the frequency responses and the H-infinity norm.

#include <Eigen/Dense>

#include "servotwin/core/state_space.hpp"

namespace servotwin::core::detail {

/// Scales a square matrix in place by a diagonal similarity D^-1 A D with powers of two (exact in
/// floating point) so that each row and column have comparable norms (Parlett & Reinsch; LAPACK
/// dgebal without permutations). Returns the diagonal of D. Rows or columns whose off-diagonal
/// part is zero are left alone.
Eigen::VectorXd balance(Eigen::MatrixXd& a);

/// The system with A balanced by that similarity (A_b = T^-1 A T, B_b = T^-1 B, C_b = C T): same
/// transfer matrix, better conditioned eigenvalues and solves for mechanically scaled models.
StateSpace balanced(const StateSpace& sys);

}  // namespace servotwin::core::detail
