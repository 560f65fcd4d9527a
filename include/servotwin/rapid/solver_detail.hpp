#pragma once
/// \file
/// Building blocks of the solvers in solver.hpp, exposed for tests and benchmarks (not a stable
/// API): the shared reduction of the problem to theta1, the thesis's Eq. 4.11-4.12 matrices, the
/// enclosures and box bounds of the exact branch and bound, the minimum-norm point of a polytope
/// with its separation certificate, and the genetic algorithm's random numbers.

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "servotwin/rapid/regression.hpp"
#include "servotwin/rapid/solver.hpp"

namespace servotwin::rapid::detail {

/// Relative pivot (of a column of unit norm) below which a regressor counts as linearly dependent
/// on the others and its parameter is fixed at 0.
inline constexpr double kRankTolerance = 1e-9;

/// The problem with theta2 eliminated (see solver.hpp): in equilibrated units
///   f(theta1, theta2*(theta1)) = ||y||^2 (1/2 ||A (s o theta1) - b||^2 + 1/2 c^2),
/// where s = column norms of the theta1 regressors over ||y||. The "excess" g = 1/2 ||A (s o theta1) - b||^2
/// is what the exact solver bounds; it lies in [0, 1/2] at theta1 = 0 scale.
class ReducedProblem {
 public:
  explicit ReducedProblem(const RegressionProblem& problem);

  /// g(theta1) (dimensionless, relative to ||y||^2).
  [[nodiscard]] double excess(const Eigen::Vector3d& theta1) const noexcept;
  /// f at theta1 with theta2 optimal: ||y||^2 (g + c^2/2).
  [[nodiscard]] double objective(const Eigen::Vector3d& theta1) const noexcept;
  /// d objective / d theta1.
  [[nodiscard]] Eigen::Vector3d objective_gradient(const Eigen::Vector3d& theta1) const noexcept;
  /// The full parameter vector: theta1 and the optimal theta2 (Eq. 4.9), dependent regressors' at 0.
  [[nodiscard]] Vector8 theta(const Eigen::Vector3d& theta1) const;
  /// The 4 x 4 matrix M of Eq. 4.12 in the form f = 1/2 mu^T M mu, mu = (1, alpha_i, alpha_1, alpha_2).
  [[nodiscard]] Eigen::Matrix4d quadratic_form() const;
  /// Unconstrained least squares (rank-revealing; dependent regressors' parameters 0).
  [[nodiscard]] Vector8 least_squares() const;
  /// theta1 regressors that least_squares() found dependent (and fixed at 0).
  [[nodiscard]] std::vector<std::string> least_squares_notes() const;

  [[nodiscard]] const Eigen::Matrix3d& a() const noexcept { return a_; }
  [[nodiscard]] const Eigen::Vector3d& b() const noexcept { return b_; }
  [[nodiscard]] double c() const noexcept { return c_; }
  /// ||y||^2, the unit of g (1 when y = 0).
  [[nodiscard]] double y_norm_squared() const noexcept { return y2_; }
  /// s: theta1~ = s o theta1 is theta1 in equilibrated units.
  [[nodiscard]] const Eigen::Vector3d& theta1_scale() const noexcept { return s1_; }
  /// Rank-deficiency notes ("regressor '-NV' is zero: delta- not identifiable, fixed at 0", ...).
  [[nodiscard]] const std::vector<std::string>& warnings() const noexcept { return warnings_; }
  /// theta2 regressors kept (true) or fixed at 0 (false), in theta order 3..7.
  [[nodiscard]] const std::array<bool, 5>& theta2_kept() const noexcept { return kept2_; }

 private:
  Eigen::Matrix3d a_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b_ = Eigen::Vector3d::Zero();
  double c_ = 0.0;
  double y2_ = 1.0;
  double y_norm_ = 1.0;
  Eigen::Vector3d s1_ = Eigen::Vector3d::Zero();
  std::array<double, kParameterCount> column_norm_{};
  // theta2~ (pivoted, first rank2 entries) = r2^-1 (t_y - c1 theta1~)
  int rank2_ = 0;
  std::array<int, 5> perm2_{};
  Eigen::Matrix<double, 5, 5> r2_ = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 3> c1_ = Eigen::Matrix<double, 5, 3>::Zero();
  Eigen::Matrix<double, 5, 1> ty_ = Eigen::Matrix<double, 5, 1>::Zero();
  std::array<bool, 5> kept2_{};
  std::vector<std::string> warnings_;
};

/// Eq. 4.11-4.12 computed literally from normal equations (P22 must be invertible): theta = T mu with
/// T = [[0, I3], [R*, -P*]], f = 1/2 (mu^T A mu + B mu + Gamma), A = T^T P T, B = -2 R^T T.
struct ThesisQuadraticForm {
  Eigen::Matrix<double, kParameterCount, 4> t;
  Eigen::Matrix4d a;
  Eigen::RowVector4d b;
  double gamma = 0.0;
};
ThesisQuadraticForm thesis_quadratic_form(const NormalEquations& ne);
double evaluate(const ThesisQuadraticForm& form, const Eigen::Vector3d& theta1) noexcept;

/// d theta1 / d(ln p, ln wn, zeta) (columns), at a point.
Eigen::Matrix3d theta1_log_jacobian(double p, double wn, double zeta) noexcept;

/// A closed interval with outward-rounded arithmetic (each result widened by one rounding unit).
struct Interval {
  double lo = 0.0, hi = 0.0;
  [[nodiscard]] double mag() const noexcept;
};

/// Box in the search coordinates x = (ln p, ln wn, zeta).
struct SearchBox {
  std::array<double, 3> lo{}, hi{};
};

/// Rigorous enclosures of theta1~ = s o theta1 (hull, from the box's vertices: every component is
/// monotone in each variable for the others fixed, Eq. 3.15) and of its Jacobian in x (natural
/// interval extension) over a box.
struct BoxEnclosure {
  std::array<Interval, 3> theta;
  std::array<std::array<Interval, 3>, 3> jacobian;  ///< [component][variable]
};
/// `column` >= 0 restricts the Jacobian to that column (the others are left zero).
BoxEnclosure enclose(const SearchBox& box, const Eigen::Vector3d& scale, int column = -1);

/// Points whose convex hull contains theta1~ of every point of the box (see solver_exact.cpp):
/// the characteristic polynomial's coefficients (p w2, p + 2 zeta w1, 1, w2 + 2 p zeta w1) are affine
/// in p, in zeta and in (w1, w2) = (wn, wn^2) separately, the arc (wn, wn^2) lies in the triangle of
/// its chord and end tangents, and theta1 is their perspective image. Returns the number of points
/// (12, fewer when the box is flat in a variable).
int hull_points(const SearchBox& box, const Eigen::Vector3d& scale, std::array<Eigen::Vector3d, 12>& points);

/// Lower bound of g over a box (the larger of the convex-hull bound and a mean-value bound, see
/// solver_exact.cpp) and the dimension whose bisection promises most.
struct BoxBound {
  double lower = 0.0;
  double hull = 0.0, mean_value = 0.0;
  std::array<Interval, 3> gradient;  ///< enclosure of dg/dx over the box (monotonicity test)
  int split = 0;                     ///< -1 when no bisection can tighten the bound
};
BoxBound bound_box(const ReducedProblem& reduced, const SearchBox& box);
/// Enclosure of dg/dx over a box (natural interval extension, outward rounded); with `only` >= 0 just
/// that component (the others are returned as the whole real line).
std::array<Interval, 3> gradient_enclosure(const ReducedProblem& reduced, const SearchBox& box, int only = -1);

/// Distance from the origin to the convex hull of `count` points (Wolfe's minimum-norm-point
/// algorithm): the nearest point found and a lower bound on the distance that holds whatever the
/// iteration reached (separating-plane certificate with the found point as normal, rounding-safe).
struct PolytopeDistance {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double lower_bound = 0.0;
};
PolytopeDistance polytope_distance(const Eigen::Vector3d* points, int count);

/// The genetic algorithm's random numbers: std::mt19937_64 bits, with the transforms written out
/// (no std distributions, whose algorithms differ between standard libraries) and the logarithm,
/// exponential and cube root evaluated by fixed sequences of IEEE operations.
class GaRandom {
 public:
  explicit GaRandom(std::uint64_t seed) : engine_(seed) {}
  /// (bits >> 11) * 2^-53, in [0, 1).
  double uniform() noexcept;
  /// Marsaglia's polar method (both values of a pair are used, in order).
  double normal() noexcept;
  /// Uniform integer in [0, n) by rejection of the incomplete top range (n > 0).
  std::uint64_t below(std::uint64_t n) noexcept;

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};
double deterministic_log(double x) noexcept;   ///< x > 0 finite
double deterministic_exp(double x) noexcept;   ///< |x| < 700
double deterministic_cbrt(double x) noexcept;  ///< x >= 0 finite

}  // namespace servotwin::rapid::detail
