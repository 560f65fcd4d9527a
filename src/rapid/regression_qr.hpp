#pragma once
// Internal kernels of the regression accumulator and of RegressionProblem: the Householder update
// of the triangular factor and the power-of-two column scaling around it.

#include <cstddef>

#include "servotwin/rapid/regression.hpp"

namespace servotwin::rapid::detail {

inline constexpr int kAugmentedColumns = kParameterCount + 1;

/// Replaces `u` by the upper-triangular factor of the stacked matrix [u; B] (so that
/// u_new^T u_new = u^T u + B^T B), where B has `rows` rows and 9 columns stored column-major with
/// leading dimension `ld` at `block`. `block` is overwritten (it holds the reflectors afterwards).
/// The diagonal of the result is non-negative when the diagonal of `u` was. Allocation-free.
void triangular_update(Matrix9& u, double* block, std::size_t ld, std::size_t rows) noexcept;

/// Rows of `u` multiplied by -1 where the diagonal is negative (an orthogonal transformation, so
/// u^T u is unchanged): a canonical sign for the factor.
void make_diagonal_nonnegative(Matrix9& u) noexcept;

/// The power of two 2^-e with max_abs * 2^-e in [1, 2); 1 for zero or non-finite input.
/// Scaling by it is exact, so it can be undone without rounding.
double power_of_two_scale(double max_abs) noexcept;

}  // namespace servotwin::rapid::detail
