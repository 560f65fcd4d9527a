#include "servotwin/core/levenberg_marquardt.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace servotwin::core {

namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
/// λ beyond this (the damping then outweighs JᵀJ by 1e16) means the step is the (tiny) scaled gradient step and still
/// fails: nothing more can be gained.
constexpr double kLambdaLimit = 1e16;

struct Evaluation {
  Eigen::VectorXd r;
  Eigen::MatrixXd j;
  bool valid = false;
};

bool all_finite(const Eigen::VectorXd& v) { return v.allFinite(); }

void check_options(const LmOptions& o, Eigen::Index n) {
  if (o.max_iterations < 0) throw std::invalid_argument("levenberg_marquardt: max_iterations must be >= 0");
  if (!(o.initial_lambda > 0.0)) throw std::invalid_argument("levenberg_marquardt: initial_lambda must be > 0");
  if (o.lower && o.lower->size() != n) throw std::invalid_argument("levenberg_marquardt: lower bound has the wrong size");
  if (o.upper && o.upper->size() != n) throw std::invalid_argument("levenberg_marquardt: upper bound has the wrong size");
  if (o.lower && o.upper && (o.lower->array() > o.upper->array()).any())
    throw std::invalid_argument("levenberg_marquardt: lower bound above upper bound");
}

Eigen::VectorXd project(Eigen::VectorXd p, const LmOptions& o) {
  if (o.lower) p = p.cwiseMax(*o.lower);
  if (o.upper) p = p.cwiseMin(*o.upper);
  return p;
}

class Evaluator {
 public:
  Evaluator(const LmResidualFunction& f, std::size_t m, const LmOptions& o) : f_(f), m_(m), o_(o) {}

  Evaluation operator()(const Eigen::VectorXd& p) {
    Evaluation e;
    e.r.resize(static_cast<Eigen::Index>(m_));
    e.j.resize(static_cast<Eigen::Index>(m_), p.size());
    ++evaluations;
    if (o_.numeric_jacobian) {
      e.valid = f_(p, e.r, nullptr) && all_finite(e.r) && central_differences(p, e.j);
    } else {
      e.valid = f_(p, e.r, &e.j) && all_finite(e.r) && e.j.allFinite();
    }
    return e;
  }

  int evaluations = 0;

 private:
  // Step cbrt(eps)·max(|p|, 1) balances truncation (h²) against rounding (eps/h).
  bool central_differences(const Eigen::VectorXd& p, Eigen::MatrixXd& j) {
    Eigen::VectorXd plus(static_cast<Eigen::Index>(m_)), minus(static_cast<Eigen::Index>(m_));
    for (Eigen::Index k = 0; k < p.size(); ++k) {
      const double h = std::cbrt(kEps) * std::max(std::abs(p[k]), 1.0);
      Eigen::VectorXd q = p;
      q[k] = p[k] + h;
      const double up = q[k];
      if (!f_(q, plus, nullptr) || !all_finite(plus)) return false;
      q[k] = p[k] - h;
      const double down = q[k];
      if (!f_(q, minus, nullptr) || !all_finite(minus)) return false;
      evaluations += 2;
      j.col(k) = (plus - minus) / (up - down);
    }
    return true;
  }

  const LmResidualFunction& f_;
  std::size_t m_;
  const LmOptions& o_;
};

/// Parameters held at a bound because the descent direction −g points out of the box.
std::vector<bool> active_set(const Eigen::VectorXd& p, const Eigen::VectorXd& g, const LmOptions& o) {
  std::vector<bool> active(static_cast<std::size_t>(p.size()), false);
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    const bool at_lower = o.lower && p[k] <= (*o.lower)[k] && g[k] > 0.0;
    const bool at_upper = o.upper && p[k] >= (*o.upper)[k] && g[k] < 0.0;
    active[static_cast<std::size_t>(k)] = at_lower || at_upper;
  }
  return active;
}

/// Solves min ‖J h + r‖² + λ‖D h‖² over the free parameters (active ones keep h = 0) by QR of the
/// stacked system.
Eigen::VectorXd damped_step(const Eigen::MatrixXd& j, const Eigen::VectorXd& r, const Eigen::VectorXd& d,
                            double lambda, const std::vector<bool>& active) {
  const Eigen::Index m = j.rows(), n = j.cols();
  std::vector<Eigen::Index> free;
  for (Eigen::Index k = 0; k < n; ++k)
    if (!active[static_cast<std::size_t>(k)]) free.push_back(k);
  const auto nf = static_cast<Eigen::Index>(free.size());
  Eigen::VectorXd h = Eigen::VectorXd::Zero(n);
  if (nf == 0) return h;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(m + nf, nf);
  for (Eigen::Index c = 0; c < nf; ++c) {
    a.col(c).head(m) = j.col(free[static_cast<std::size_t>(c)]);
    a(m + c, c) = std::sqrt(lambda) * d[free[static_cast<std::size_t>(c)]];
  }
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m + nf);
  b.head(m) = -r;
  const Eigen::VectorXd hf = a.colPivHouseholderQr().solve(b);
  for (Eigen::Index c = 0; c < nf; ++c) h[free[static_cast<std::size_t>(c)]] = hf[c];
  return h;
}

}  // namespace

bool converged(LmStatus status) noexcept {
  switch (status) {
    case LmStatus::kGradientSmall:
    case LmStatus::kStepSmall:
    case LmStatus::kCostSmall:
    case LmStatus::kReductionSmall:
      return true;
    case LmStatus::kMaxIterations:
    case LmStatus::kStalled:
    case LmStatus::kInvalidStart:
      return false;
  }
  return false;
}

std::string to_string(LmStatus status) {
  switch (status) {
    case LmStatus::kGradientSmall: return "gradient small";
    case LmStatus::kStepSmall: return "step small";
    case LmStatus::kCostSmall: return "cost small";
    case LmStatus::kReductionSmall: return "cost reduction small";
    case LmStatus::kMaxIterations: return "maximum iterations";
    case LmStatus::kStalled: return "stalled";
    case LmStatus::kInvalidStart: return "invalid start";
  }
  return "unknown";
}

Eigen::MatrixXd least_squares_covariance(const Eigen::MatrixXd& jacobian, double sigma2, int* rank) {
  const Eigen::Index n = jacobian.cols();
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(n, n, kNan);
  if (n == 0 || jacobian.rows() == 0) {
    if (rank) *rank = 0;
    return cov;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  const double threshold = static_cast<double>(std::max(jacobian.rows(), n)) * kEps * s[0];
  int r = 0;
  for (Eigen::Index k = 0; k < s.size(); ++k)
    if (s[k] > threshold) ++r;
  if (rank) *rank = r;
  if (r < n || !std::isfinite(sigma2)) return cov;
  const Eigen::MatrixXd& v = svd.matrixV();
  cov = sigma2 * v * s.cwiseAbs2().cwiseInverse().asDiagonal() * v.transpose();
  return cov;
}

LmResult levenberg_marquardt(const LmResidualFunction& residual_function, const Eigen::VectorXd& initial,
                             std::size_t residual_count, const LmOptions& options) {
  const Eigen::Index n = initial.size();
  if (residual_count == 0) throw std::invalid_argument("levenberg_marquardt: no residuals");
  check_options(options, n);
  Evaluator evaluate(residual_function, residual_count, options);

  LmResult result;
  result.parameters = project(initial, options);
  Evaluation current = evaluate(result.parameters);
  if (!current.valid) {
    result.status = LmStatus::kInvalidStart;
    result.message = "the residual function rejected the initial parameters or returned non-finite values there";
    result.evaluations = evaluate.evaluations;
    result.cost = result.initial_cost = kNan;
    return result;
  }
  double cost = 0.5 * current.r.squaredNorm();
  result.initial_cost = cost;

  // Marquardt scaling: running maximum of the column norms (zero columns get 1 so D is invertible).
  Eigen::VectorXd d = current.j.colwise().norm().transpose();
  for (Eigen::Index k = 0; k < n; ++k)
    if (!(d[k] > 0.0)) d[k] = 1.0;
  // D holds J's column norms, so lambda ||D h||^2 is commensurate with ||J h||^2 and lambda is
  // dimensionless: multiplying it by max D^2 as well would make the damping depend on the units
  // of the residuals (a fit in um would take other steps than the same fit in mm).
  double lambda = options.initial_lambda;
  double nu = 2.0;

  result.status = LmStatus::kMaxIterations;
  result.message = "reached the iteration limit before a stopping criterion held";
  int iteration = 0;
  while (true) {
    const Eigen::VectorXd g = current.j.transpose() * current.r;
    const std::vector<bool> active = active_set(result.parameters, g, options);
    // Projected gradient: components held at a bound are optimal there.
    double scaled_gradient = 0.0;
    for (Eigen::Index k = 0; k < n; ++k)
      if (!active[static_cast<std::size_t>(k)]) scaled_gradient = std::max(scaled_gradient, std::abs(g[k]) / d[k]);
    if (cost <= options.cost_tolerance) {
      result.status = LmStatus::kCostSmall;
      result.message = "cost below tolerance";
      break;
    }
    if (scaled_gradient <= options.gradient_tolerance * std::max(current.r.norm(), 1e-300)) {
      result.status = LmStatus::kGradientSmall;
      result.message = "scaled gradient below tolerance";
      break;
    }
    if (iteration >= options.max_iterations) break;
    ++iteration;

    const Eigen::VectorXd step = damped_step(current.j, current.r, d, lambda, active);
    const Eigen::VectorXd trial_p = project(result.parameters + step, options);
    const Eigen::VectorXd h = trial_p - result.parameters;
    const double step_norm = (d.asDiagonal() * h).norm();
    LmIteration record{iteration, cost, lambda, step_norm, kNan, false};
    if (step_norm <= options.step_tolerance * ((d.asDiagonal() * result.parameters).norm() + options.step_tolerance)) {
      if (options.record_history) result.history.push_back(record);
      result.status = LmStatus::kStepSmall;
      result.message = "step below tolerance";
      break;
    }
    Evaluation trial = evaluate(trial_p);
    const double predicted = cost - 0.5 * (current.r + current.j * h).squaredNorm();
    double ratio = kNan;
    if (trial.valid) {
      const double trial_cost = 0.5 * trial.r.squaredNorm();
      const double actual = cost - trial_cost;
      ratio = predicted > 0.0 ? actual / predicted : (actual > 0.0 ? 1.0 : -1.0);
      record.gain_ratio = ratio;
      if (actual > 0.0 && ratio > 0.0) {
        record.accepted = true;
        record.cost = trial_cost;
        result.parameters = trial_p;
        current = std::move(trial);
        const double previous = cost;
        cost = trial_cost;
        d = d.cwiseMax(current.j.colwise().norm().transpose());
        lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * ratio - 1.0, 3));
        nu = 2.0;
        if (options.record_history) result.history.push_back(record);
        if (actual <= options.relative_reduction_tolerance * previous) {
          result.status = LmStatus::kReductionSmall;
          result.message = "relative cost reduction below tolerance";
          break;
        }
        continue;
      }
    }
    if (options.record_history) result.history.push_back(record);
    lambda *= nu;
    nu *= 2.0;
    if (lambda > kLambdaLimit) {
      result.status = LmStatus::kStalled;
      result.message = "no step reduces the cost even with very large damping";
      break;
    }
  }

  result.iterations = iteration;
  result.evaluations = evaluate.evaluations;
  result.cost = cost;
  result.residual = current.r;
  result.jacobian = current.j;
  const auto m = static_cast<Eigen::Index>(residual_count);
  if (options.covariance_scale == LmCovarianceScale::kKnown)
    result.sigma2 = 1.0;
  else
    result.sigma2 = m > n ? current.r.squaredNorm() / static_cast<double>(m - n) : kNan;
  result.covariance = least_squares_covariance(current.j, result.sigma2, &result.jacobian_rank);
  return result;
}

}  // namespace servotwin::core
