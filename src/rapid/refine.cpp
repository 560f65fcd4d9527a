#include "servotwin/rapid/refine.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

#include "servotwin/core/error.hpp"
#include "servotwin/core/levenberg_marquardt.hpp"

namespace servotwin::rapid {

namespace {

constexpr std::size_t kParameters = 8;
/// Relative slack when deciding that the start lies within the bounds (the exact solver returns
/// points on the bounds up to rounding).
constexpr double kBoundSlack = 1e-9;
/// Forward-difference step relative to max(|parameter|, 1): the parameters are of order 1, and
/// the simulated positions carry about 1e-12 relative rounding from the event location.
constexpr double kDifferenceStep = 1e-6;

enum Index : std::size_t { kLogP, kLogWn, kZeta, kB0, kB1, kB2, kD0, kD1 };

/// a1, a2, a3 of the characteristic polynomial (s + p)(s^2 + 2 zeta wn s + wn^2).
std::array<double, 3> characteristic(double p, double wn, double zeta) {
  return {p + 2.0 * zeta * wn, wn * wn + 2.0 * zeta * wn * p, p * wn * wn};
}

void check_records(std::span<const TrackingRecord> records) {
  if (records.empty()) throw core::InputError({"", 0, 0, "records"}, "no captures to refine the model on");
  for (std::size_t r = 0; r < records.size(); ++r) {
    const auto& rec = records[r];
    const std::string field = "records[" + std::to_string(r) + "]";
    if (rec.command.size() != rec.actual.size()) {
      throw core::InputError({"", 0, 0, field}, "command and actual position differ in length (" +
                                                    std::to_string(rec.command.size()) + " vs " +
                                                    std::to_string(rec.actual.size()) + " samples)");
    }
    if (rec.command.size() < 2) throw core::InputError({"", 0, 0, field}, "needs at least 2 samples");
    for (std::size_t k = 0; k < rec.command.size(); ++k) {
      if (!std::isfinite(rec.command[k]) || !std::isfinite(rec.actual[k])) {
        throw core::InputError({"", 0, 0, field + ".sample[" + std::to_string(k) + "]"}, "non-finite sample");
      }
    }
  }
}

bool within(double v, double lo, double hi) {
  return v >= lo * (1.0 - kBoundSlack) && v <= hi * (1.0 + kBoundSlack);
}

/// The factorization of the start's characteristic polynomial that lies within the bounds.
PoleFactorization feasible_factorization(const ModelCoefficients& c, const Bounds& b) {
  if (c.a2 != 0.0 && std::isfinite(c.a2)) {
    const Eigen::Vector3d theta1(c.a3 / c.a2, c.a1 / c.a2, 1.0 / c.a2);
    for (const PoleFactorization& f : pole_factorizations(theta1)) {
      if (within(f.p, b.p_min, b.p_max) && within(f.wn, b.wn_min, b.wn_max) && within(f.zeta, b.zeta_min, b.zeta_max)) {
        return {std::clamp(f.p, b.p_min, b.p_max), std::clamp(f.wn, b.wn_min, b.wn_max),
                std::clamp(f.zeta, b.zeta_min, b.zeta_max)};
      }
    }
  }
  throw core::InputError({"", 0, 0, "start"},
                         "the model's poles are not (s + p)(s^2 + 2 zeta wn s + wn^2) within the bounds: refine an "
                         "exact or ga solution, not an unconstrained one");
}

double rms_tracking_error(std::span<const TrackingRecord> records) {
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& r : records) {
    for (std::size_t k = 0; k < r.command.size(); ++k) sum += (r.command[k] - r.actual[k]) * (r.command[k] - r.actual[k]);
    n += r.command.size();
  }
  return std::sqrt(sum / static_cast<double>(n));
}

/// Coefficients of the full parameter vector q; `error` is the length scale of the friction
/// parameters (the RMS measured tracking error).
ModelCoefficients coefficients_of(const std::array<double, kParameters>& q, double error) {
  ModelCoefficients c;
  const auto [a1, a2, a3] = characteristic(std::exp(q[kLogP]), std::exp(q[kLogWn]), q[kZeta]);
  c.a1 = a1;
  c.a2 = a2;
  c.a3 = a3;
  c.b0 = q[kB0];
  // b1, b2 relative to the current a1, a2: moving the poles moves the zeros with them, which
  // keeps the parameters nearly uncorrelated (with fixed scales b2 ~ a2 forms a long valley).
  c.b1 = q[kB1] * c.a1;
  c.b2 = q[kB2] * c.a2;
  c.d0 = q[kD0] * c.a2 * error;  // friction as the static deflection it causes, d / a2
  c.d1 = q[kD1] * c.a2 * error;
  return c;
}

/// The parameters that move (the others keep the start's value; see the header).
struct Layout {
  std::array<double, kParameters> start{};
  std::vector<std::size_t> free;
};

Layout layout_of(const ModelCoefficients& c, const PoleFactorization& f, double error) {
  Layout l;
  const std::array<double, 3> a = characteristic(f.p, f.wn, f.zeta);
  l.start = {std::log(f.p), std::log(f.wn), f.zeta, c.b0, c.b1 / a[0], c.b2 / a[1], c.d0 / (a[1] * error), c.d1 / (a[1] * error)};
  const std::array<double, kParameters> raw = {f.p, f.wn, f.zeta, c.b0, c.b1, c.b2, c.d0, c.d1};
  for (std::size_t i = 0; i < kParameters; ++i)
    if (raw[i] != 0.0) l.free.push_back(i);
  return l;
}

/// Simulates the model of full parameters q on every record; residuals x_model - x.
class Simulator {
 public:
  Simulator(double ts, std::span<const TrackingRecord> records, int shift, double error)
      : ts_(ts), records_(records), shift_(shift), error_(error) {
    for (const auto& r : records) samples_ += r.command.size();
  }

  [[nodiscard]] std::size_t samples() const { return samples_; }

  bool residuals(const std::array<double, kParameters>& q, Eigen::VectorXd& out) {
    ++simulations;
    const ModelCoefficients c = coefficients_of(q, error_);
    try {
      const AxisModel model(c, ts_);
      Eigen::Index row = 0;
      for (const auto& r : records_) {
        ModelSimulationOptions options;
        options.command_shift = shift_;
        options.initial_position = r.actual.front();
        model.simulate_into(r.command, response_, options);
        for (std::size_t k = 0; k < r.command.size(); ++k) out[row++] = response_.position[k] - r.actual[k];
      }
    } catch (const core::InputError&) {
      return false;  // coefficients out of the model's domain (overflowing growth): reject the step
    }
    return out.allFinite();
  }

  int simulations = 0;

 private:
  double ts_;
  std::span<const TrackingRecord> records_;
  int shift_;
  double error_;
  std::size_t samples_ = 0;
  ModelResponse response_;
};

void set_bounds(const Layout& l, const Bounds& b, core::LmOptions& o) {
  const auto n = static_cast<Eigen::Index>(l.free.size());
  Eigen::VectorXd lower = Eigen::VectorXd::Constant(n, -std::numeric_limits<double>::infinity());
  Eigen::VectorXd upper = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity());
  for (Eigen::Index i = 0; i < n; ++i) {
    switch (l.free[static_cast<std::size_t>(i)]) {
      case kLogP: lower[i] = std::log(b.p_min), upper[i] = std::log(b.p_max); break;
      case kLogWn: lower[i] = std::log(b.wn_min), upper[i] = std::log(b.wn_max); break;
      case kZeta: lower[i] = b.zeta_min, upper[i] = b.zeta_max; break;
      default: break;
    }
  }
  o.lower = lower;
  o.upper = upper;
}

/// Bounds active at the result, with the cost's derivative along each bounded variable.
std::vector<ActiveBound> active_bounds(const Layout& l, const core::LmResult& r, const core::LmOptions& o) {
  std::vector<ActiveBound> active;
  const Eigen::VectorXd gradient = r.jacobian.transpose() * r.residual;  // d cost / d q
  for (std::size_t i = 0; i < l.free.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    const std::size_t which = l.free[i];
    if (which > kZeta) continue;
    const double q = r.parameters[e];
    const double per_variable = which == kZeta ? 1.0 : std::exp(q);  // d variable / d q
    const double g = gradient[e] / per_variable;
    const char* names[3][2] = {{"p_min", "p_max"}, {"wn_min", "wn_max"}, {"zeta_min", "zeta_max"}};
    if (q <= (*o.lower)[e]) active.push_back({names[which][0], g});
    if (q >= (*o.upper)[e]) active.push_back({names[which][1], -g});
  }
  return active;
}

}  // namespace

Refinement refine_output_error(const ModelCoefficients& start, double ts, std::span<const TrackingRecord> records,
                               const Bounds& bounds, const RefineOptions& options) {
  const auto clock_start = std::chrono::steady_clock::now();
  validate(bounds);
  check_records(records);
  const PoleFactorization poles = feasible_factorization(start, bounds);

  const double error = rms_tracking_error(records);
  const double friction_scale = error > 0.0 ? error : 1.0;  // length scale of the friction parameters

  const Layout layout = layout_of(start, poles, friction_scale);
  Simulator simulator(ts, records, options.command_shift, friction_scale);
  auto full = [&](const Eigen::VectorXd& free) {
    std::array<double, kParameters> q = layout.start;
    for (std::size_t i = 0; i < layout.free.size(); ++i) q[layout.free[i]] = free[static_cast<Eigen::Index>(i)];
    return q;
  };
  core::LmOptions lm;
  lm.max_iterations = options.max_iterations;
  lm.relative_reduction_tolerance = options.relative_reduction_tolerance;
  lm.record_history = false;
  lm.cost_tolerance = 0.5 * static_cast<double>(simulator.samples()) * std::pow(options.residual_floor * error, 2);
  set_bounds(layout, bounds, lm);
  // Forward differences: one simulation per parameter (central ones would double the cost for
  // accuracy the damped steps do not need).
  Eigen::VectorXd shifted(static_cast<Eigen::Index>(simulator.samples()));
  const core::LmResidualFunction residual = [&](const Eigen::VectorXd& free, Eigen::VectorXd& r,
                                                Eigen::MatrixXd* jacobian) {
    if (!simulator.residuals(full(free), r)) return false;
    if (jacobian == nullptr) return true;
    for (Eigen::Index i = 0; i < free.size(); ++i) {
      Eigen::VectorXd q = free;
      const double h = kDifferenceStep * std::max(std::abs(free[i]), 1.0);
      // Step into the box, so that a parameter on its upper bound is differentiated inside.
      const double upper = (*lm.upper)[i];
      q[i] = free[i] + h <= upper ? free[i] + h : free[i] - h;
      if (!simulator.residuals(full(q), shifted)) return false;
      jacobian->col(i) = (shifted - r) / (q[i] - free[i]);
    }
    return true;
  };

  Eigen::VectorXd initial(static_cast<Eigen::Index>(layout.free.size()));
  for (std::size_t i = 0; i < layout.free.size(); ++i) initial[static_cast<Eigen::Index>(i)] = layout.start[layout.free[i]];
  const core::LmResult lm_result = core::levenberg_marquardt(residual, initial, simulator.samples(), lm);
  if (lm_result.status == core::LmStatus::kInvalidStart) {
    throw core::InputError({"", 0, 0, "start"}, "the start model cannot be simulated on these captures");
  }

  Refinement out;
  const std::array<double, kParameters> q = full(lm_result.parameters);
  out.coefficients = coefficients_of(q, friction_scale);
  out.p = std::exp(q[kLogP]);
  out.wn = std::exp(q[kLogWn]);
  out.zeta = q[kZeta];
  out.active = active_bounds(layout, lm_result, lm);
  out.initial_cost = lm_result.initial_cost;
  out.cost = lm_result.cost;
  out.iterations = lm_result.iterations;
  out.simulations = simulator.simulations;
  out.converged = lm_result.converged();
  out.stop_reason = lm_result.message;
  out.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - clock_start).count();
  return out;
}

}  // namespace servotwin::rapid
