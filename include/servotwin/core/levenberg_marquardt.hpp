#pragma once
/// \file
/// Levenberg–Marquardt for nonlinear least squares min ½‖r(p)‖² (seed catalog C2.7), on Eigen.
///
/// The caller supplies residuals and (optionally) their Jacobian; weighting is the caller's job
/// (return W^{1/2} r and W^{1/2} J), so the same solver serves absolute, relative and
/// standard-deviation weighted problems. Each step solves the damped problem
///   min ‖J h + r‖² + λ ‖D h‖²
/// by QR of the stacked matrix [J; √λ D] rather than forming JᵀJ (its condition number is the
/// square of J's). D is Marquardt's scaling: the running maximum of the column norms of J
/// (MINPACK's choice), so the iteration is invariant to rescaling a parameter. λ follows Nielsen's
/// rule (catalog C2.7 suggestion). Box bounds: a parameter on a bound whose descent direction points
/// out of the box is held there for the step (active set), the step is solved for the others, the
/// trial point is projected onto the box, and the gradient test uses the projected gradient. Problems that need an unconstrained parameterization (log ω, log ζ) do that themselves.

#include <Eigen/Dense>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace servotwin::core {

/// Evaluates residuals r(p) (size m) and, when `jacobian` is non-null, J = ∂r/∂p (m×n, already
/// sized by the solver). Returns false when p is outside the model's domain (the step is then
/// rejected like a step that increases the cost).
using LmResidualFunction =
    std::function<bool(const Eigen::VectorXd& p, Eigen::VectorXd& residual, Eigen::MatrixXd* jacobian)>;

/// How the covariance of the estimate is scaled.
enum class LmCovarianceScale {
  kEstimated,  ///< σ² = ‖r‖²/(m−n): residuals carry unknown but equal noise
  kKnown,      ///< σ² = 1: residuals are already divided by their standard deviations
};

struct LmOptions {
  int max_iterations = 200;          ///< iterations (accepted or rejected steps) before giving up
  double initial_lambda = 1e-3;      ///< λ0, dimensionless: D² already carries JᵀJ's scale (Nielsen's τ; the catalog's example uses 1e-7)
  double gradient_tolerance = 1e-10; ///< stop when max_j |g_j| / D_j ≤ this·‖r‖ over the free parameters (scaled first-order optimality)
  double step_tolerance = 1e-12;     ///< stop when ‖D h‖ ≤ this·(‖D p‖ + this)
  double cost_tolerance = 0.0;       ///< stop when ½‖r‖² ≤ this (exact-fit problems)
  double relative_reduction_tolerance = 1e-14;  ///< stop when an accepted step reduces the cost by less than this fraction
  std::optional<Eigen::VectorXd> lower;  ///< box bounds (each entry may be -inf); size n when given
  std::optional<Eigen::VectorXd> upper;  ///< box bounds (each entry may be +inf); size n when given
  bool numeric_jacobian = false;     ///< ignore the callback's Jacobian and use central differences
  LmCovarianceScale covariance_scale = LmCovarianceScale::kEstimated;
  bool record_history = true;        ///< keep one LmIteration per iteration
};

/// Why the iteration stopped.
enum class LmStatus {
  kGradientSmall,    ///< scaled gradient below tolerance (first-order optimal)
  kStepSmall,        ///< step below tolerance
  kCostSmall,        ///< cost below cost_tolerance
  kReductionSmall,   ///< relative cost reduction below tolerance
  kMaxIterations,    ///< iteration limit reached before any criterion held
  kStalled,          ///< λ grew beyond any useful size without an acceptable step
  kInvalidStart,     ///< the callback rejected the initial point or produced non-finite values there
};

/// True for the statuses that mean convergence.
[[nodiscard]] bool converged(LmStatus status) noexcept;
/// Short name ("gradient small", "maximum iterations", ...).
[[nodiscard]] std::string to_string(LmStatus status);

/// One iteration of the history.
struct LmIteration {
  int iteration = 0;
  double cost = 0.0;        ///< ½‖r‖² after the iteration
  double lambda = 0.0;      ///< damping used for the step
  double step_norm = 0.0;   ///< ‖D h‖ of the trial step
  double gain_ratio = 0.0;  ///< actual / predicted reduction (NaN when the trial point was invalid)
  bool accepted = false;
};

struct LmResult {
  Eigen::VectorXd parameters;
  Eigen::VectorXd residual;       ///< r at the solution
  Eigen::MatrixXd jacobian;       ///< J at the solution
  double cost = 0.0;              ///< ½‖r‖² at the solution
  double initial_cost = 0.0;
  int iterations = 0;
  int evaluations = 0;            ///< residual evaluations (Jacobian evaluations included)
  LmStatus status = LmStatus::kMaxIterations;
  std::string message;            ///< human-readable reason for stopping
  std::vector<LmIteration> history;
  /// Residual variance used for the covariance: ‖r‖²/(m−n) or 1 (NaN when m ≤ n for kEstimated).
  double sigma2 = 0.0;
  /// σ² (JᵀJ)⁻¹ at the solution, computed from the SVD of J; entries are NaN when J is rank
  /// deficient (a parameter is not identifiable from the data) or when σ² is undefined.
  Eigen::MatrixXd covariance;
  int jacobian_rank = 0;          ///< numerical rank of J (SVD, relative threshold n·m·eps)

  [[nodiscard]] bool converged() const noexcept { return core::converged(status); }
};

/// Minimizes ½‖r(p)‖² from `initial`. Throws std::invalid_argument for inconsistent sizes
/// (bounds of the wrong size, lower > upper, m = 0) — programming errors; a bad starting point is
/// reported as status kInvalidStart instead.
LmResult levenberg_marquardt(const LmResidualFunction& residual_function, const Eigen::VectorXd& initial,
                             std::size_t residual_count, const LmOptions& options = {});

/// σ² (JᵀJ)⁻¹ from the SVD of J (NaN-filled when rank deficient); `rank` receives the numerical rank.
Eigen::MatrixXd least_squares_covariance(const Eigen::MatrixXd& jacobian, double sigma2, int* rank = nullptr);

}  // namespace servotwin::core
