#pragma once
// Internal to servotwin_core: diagonal balancing shared by the root finder and the matrix
// exponential.

#include <Eigen/Dense>

namespace servotwin::core::detail {

/// Scales a square matrix in place by a diagonal similarity D^-1 A D with powers of two (exact in
/// floating point) so that each row and column have comparable norms (Parlett & Reinsch; LAPACK
/// dgebal without permutations). Returns the diagonal of D. Rows or columns whose off-diagonal
/// part is zero are left alone.
Eigen::VectorXd balance(Eigen::MatrixXd& a);

}  // namespace servotwin::core::detail
