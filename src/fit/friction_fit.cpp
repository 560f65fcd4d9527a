#include "servotwin/fit/friction_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "friction_model.hpp"
#include "misfit.hpp"
#include "servotwin/core/levenberg_marquardt.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;
using detail::ChainParameters;
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

/// θ = (ln Jm, ln Jl, ln k, ln bs, bv/bv_ref, Mm/T_ref, Ml/T_ref[, ln p][, T ωz]): logs keep the
/// positive quantities positive; the three that may be 0 are scaled to order one (T_ref the median
/// excitation amplitude, bv_ref = Jm ωz of the start) so that LM's central differences and box
/// bounds act on comparable numbers. The lag pole p and the delay T, when the linear fit has them,
/// are fitted again: friction bends the linear fit's phase, and with it its lag. On the load side
/// θ[kJm] is ln J (J = Jm + Jl), θ[kJl] the logit of the motor's share s = Jm/J, and k, bs carry
/// the factor 4s(1 − s): the linear part's resonance (ωp² = k J/(Jm Jl)) is then free of s, which
/// only the friction's describing functions tell (linear data leave it where it starts, 1/2).
enum Index : Eigen::Index { kJm, kJl, kK, kBs, kBv, kMm, kMl, kCount };

/// What the residuals need besides θ.
struct Context {
  double viscous = 1.0;   ///< bv_ref
  double torque = 1.0;    ///< T_ref
  double time = 1.0;      ///< 1/ωz of the start, the delay's unit
  PlantModel linear;      ///< the linear fit: output kind, lag and delay present or not
  SensorSide sensor = SensorSide::kMotor;
};

/// Where the lag and delay sit in θ (absent: -1), and θ's size.
struct Layout {
  Eigen::Index lag = -1, delay = -1, size = kCount;
  explicit Layout(const PlantModel& m) {
    if (m.lag_pole_rad_s) lag = size++;
    if (m.delay_s) delay = size++;
  }
};

/// The linear fit's structure (output kind) with θ's lag and delay.
PlantModel actuator_of(const Eigen::VectorXd& t, const Context& c) {
  PlantModel m;
  m.output = c.linear.output;
  const Layout l(c.linear);
  if (l.lag >= 0) m.lag_pole_rad_s = std::exp(t[l.lag]);
  if (l.delay >= 0) m.delay_s = t[l.delay] * c.time;
  return m;
}

/// The load side's share s = Jm/J from its logit θ[kJl].
double motor_share(const Eigen::VectorXd& t) { return 1.0 / (1.0 + std::exp(-t[kJl])); }

ChainParameters physical_of(const Eigen::VectorXd& t, const Context& c) {
  const double viscous = t[kBv] * c.viscous, mm = t[kMm] * c.torque, ml = t[kMl] * c.torque;
  if (c.sensor == SensorSide::kMotor)
    return {std::exp(t[kJm]), std::exp(t[kJl]), std::exp(t[kK]), std::exp(t[kBs]), viscous, mm, ml};
  const double total = std::exp(t[kJm]), share = motor_share(t), q = 4.0 * share * (1.0 - share);
  return {share * total, (1.0 - share) * total, q * std::exp(t[kK]), q * std::exp(t[kBs]), viscous, mm, ml};
}

struct Point {
  double omega = 0.0;
  Complex log_meas;
  double velocity = 0.0;  ///< the measured side's |V| = |P|·T (velocity output) or ω|P|·T (position)
  double weight = 1.0;    ///< detail::log_residual_weight, as the linear fit's
  /// The weights of the log error's real and imaginary parts: `weight`, lowered where the measured
  /// amplitude's own noise moves the model (errors_in_variables).
  double weight_re = 1.0, weight_im = 1.0;
};

/// |V| of a measured point: the input amplitude times the measured gain (times ω for a position
/// output).
double velocity_of(const core::FrequencyPoint& q, OutputKind output) {
  return std::abs(q.value) * q.amplitude * (output == OutputKind::kPosition ? kTwoPi * q.freq_hz : 1.0);
}

bool residuals(const Eigen::VectorXd& t, const std::vector<Point>& points, const Context& c, Eigen::VectorXd& r) {
  if ((t.head<4>().array().abs() > 700.0).any()) return false;
  const ChainParameters p = physical_of(t, c);
  const PlantModel act = actuator_of(t, c);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Complex m = detail::chain_response(points[k].omega, points[k].velocity, p, act, c.sensor);
    if (!std::isfinite(m.real()) || !std::isfinite(m.imag()) || m == 0.0) return false;
    const Complex e = std::log(m) - points[k].log_meas;
    r[static_cast<Eigen::Index>(2 * k)] = points[k].weight_re * e.real();
    r[static_cast<Eigen::Index>(2 * k + 1)] = points[k].weight_im * std::remainder(e.imag(), kTwoPi);
  }
  return true;
}

/// sqrt(Σ|ln(P_model/P_meas)|²/m) without the weights (FitResult::rms_log_error).
double unweighted_rms(const Eigen::VectorXd& r, const std::vector<Point>& points) {
  double sum = 0.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const double re = r[static_cast<Eigen::Index>(2 * k)] / points[k].weight_re;
    const double im = r[static_cast<Eigen::Index>(2 * k + 1)] / points[k].weight_im;
    sum += re * re + im * im;
  }
  return std::sqrt(sum / static_cast<double>(points.size()));
}

/// σ²(JᵀJ)⁻¹ over the free parameters; a parameter held fixed (`fixed`: bv of an integrator, the
/// split on the load side, pinned by equal bounds) is not estimated, so its column is left out and
/// its row and column are zero (keeping it would spread the data's information over a parameter
/// that cannot move).
Eigen::MatrixXd free_covariance(const core::LmResult& lm, bool known_std, const std::vector<Eigen::Index>& fixed) {
  const Eigen::Index n = lm.jacobian.cols();
  std::vector<Eigen::Index> keep;
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::find(fixed.begin(), fixed.end(), i) == fixed.end()) keep.push_back(i);
  Eigen::MatrixXd j(lm.jacobian.rows(), static_cast<Eigen::Index>(keep.size()));
  for (std::size_t c = 0; c < keep.size(); ++c) j.col(static_cast<Eigen::Index>(c)) = lm.jacobian.col(keep[c]);
  const double dof = static_cast<double>(j.rows() - j.cols());
  const double sigma2 = known_std ? 1.0 : dof > 0.0 ? lm.residual.squaredNorm() / dof : kNan;
  const Eigen::MatrixXd free = core::least_squares_covariance(j, sigma2);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t a = 0; a < keep.size(); ++a)
    for (std::size_t b = 0; b < keep.size(); ++b)
      c(keep[a], keep[b]) = free(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  return c;
}

/// Errors in variables: each point's model uses its measured amplitude |V| = |P_meas|·T, so the
/// measurement's noise enters the model too. With ln P_meas = ln P + δr + jδi (δr, δi of equal
/// variance s²) and g = ∂ln P_model/∂ln|V| (complex), the log error is
/// e = (g − 1)δr − jδi: Re e has variance (Re g − 1)² s², Im e (Im g² + 1) s². Near the
/// antiresonance, where the load's describing function sets the damping, |Re g − 1| reaches 5–10
/// and the plain weights would read that noise as misfit (reduced χ² 4 on 0.5 % noise). The
/// weights are divided by those factors, never raised (where g ≈ 1, friction-dominated points
/// whose magnitude follows the measurement, the model's own error, not the noise, is what is
/// left: such points keep their weight). g by central differences at the first solution.
void errors_in_variables(const Eigen::VectorXd& t, const Context& c, std::vector<Point>& points) {
  const ChainParameters p = physical_of(t, c);
  const PlantModel act = actuator_of(t, c);
  constexpr double h = 1e-5;
  for (Point& q : points) {
    const Complex up = detail::chain_response(q.omega, q.velocity * (1.0 + h), p, act, c.sensor);
    const Complex down = detail::chain_response(q.omega, q.velocity * (1.0 - h), p, act, c.sensor);
    const Complex g = (std::log(up) - std::log(down)) / (std::log1p(h) - std::log1p(-h));
    if (!std::isfinite(g.real()) || !std::isfinite(g.imag())) continue;
    q.weight_re = q.weight / std::max(1.0, std::abs(g.real() - 1.0));
    q.weight_im = q.weight / std::sqrt(1.0 + g.imag() * g.imag());
  }
}

/// A run is better when it converged and the other did not, else when its cost is lower.
bool better(const core::LmResult& run, const core::LmResult& best) {
  if (run.status == core::LmStatus::kInvalidStart) return false;
  if (!std::isfinite(best.cost)) return true;
  if (run.converged() != best.converged()) return run.converged();
  return run.cost < best.cost;
}

/// A value and its standard deviation from θ's covariance by the delta method, g = ∂value/∂θ.
Estimate delta(double value, const Eigen::VectorXd& g, const Eigen::MatrixXd& c) {
  return {value, std::sqrt(std::max(0.0, g.dot(c * g)))};
}

/// Numerical gradient of a scalar function of θ (central differences on θ's own scale).
template <class F>
Eigen::VectorXd gradient(const Eigen::VectorXd& t, F f) {
  Eigen::VectorXd g(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::abs(t[i]));
    Eigen::VectorXd a = t, b = t;
    a[i] += h;
    b[i] -= h;
    g[i] = (f(a) - f(b)) / (2.0 * h);
  }
  return g;
}

void fill_estimates(CoulombFit& out, const Eigen::VectorXd& t, const Eigen::MatrixXd& c, const Context& ctx, RigidKind rigid) {
  const ChainParameters p = physical_of(t, ctx);
  const bool load = ctx.sensor == SensorSide::kLoad;
  auto log_param = [&](Index i) {
    return Estimate{std::exp(t[i]), std::exp(t[i]) * std::sqrt(std::max(0.0, c(i, i)))};
  };
  auto scaled_param = [&](Index i, double scale) {
    return Estimate{t[i] * scale, scale * std::sqrt(std::max(0.0, c(i, i)))};
  };
  // On the load side the inertias, k and bs are functions of θ: delta method.
  const auto physical = [&](double ChainParameters::*member) {
    const auto value = [&](const Eigen::VectorXd& x) { return physical_of(x, ctx).*member; };
    return delta(p.*member, gradient(t, value), c);
  };
  out.motor_inertia = load ? physical(&ChainParameters::jm) : log_param(kJm);
  out.load_inertia = load ? physical(&ChainParameters::jl) : log_param(kJl);
  out.stiffness = load ? physical(&ChainParameters::k) : log_param(kK);
  out.shaft_damping = load ? physical(&ChainParameters::bs) : log_param(kBs);
  out.total_inertia = load ? log_param(kJm) : Estimate{p.jm + p.jl, kNan};
  if (load) {
    const double share = motor_share(t);
    out.motor_share = {share, share * (1.0 - share) * std::sqrt(std::max(0.0, c(kJl, kJl)))};
  } else {
    out.motor_share = {p.jm / (p.jm + p.jl), kNan};
  }
  out.viscous_damping = scaled_param(kBv, ctx.viscous);
  out.motor_coulomb = scaled_param(kMm, ctx.torque);
  out.load_coulomb = scaled_param(kMl, ctx.torque);
  out.model = detail::chain_linear_part(p, actuator_of(t, ctx), rigid, ctx.sensor);
  const Layout l(ctx.linear);
  // K = p/Jm (p/(Jm + Jl) on the load side; without a lag p = 1): ln K = ln p − θ[kJm].
  double var_ln_gain = c(kJm, kJm);
  if (l.lag >= 0) var_ln_gain += c(l.lag, l.lag) - 2.0 * c(kJm, l.lag);
  out.gain = {out.model.gain, out.model.gain * std::sqrt(std::max(0.0, var_ln_gain))};
  out.lag_pole_rad_s = l.lag >= 0 ? log_param(static_cast<Index>(l.lag)) : Estimate{kNan, kNan};
  out.delay_s = l.delay >= 0 ? scaled_param(static_cast<Index>(l.delay), ctx.time) : Estimate{kNan, kNan};
  out.theta = t;
  out.covariance = c;
  auto modal = [&](int which) {
    return [&, which](const Eigen::VectorXd& x) {
      const PlantModel lp = detail::chain_linear_part(physical_of(x, ctx), actuator_of(x, ctx), rigid, ctx.sensor);
      const Mode& m = lp.modes.front();
      switch (which) {
        case 0: return m.antiresonance.omega_rad_s;
        case 1: return m.antiresonance.zeta;
        case 2: return m.resonance.omega_rad_s;
        case 3: return m.resonance.zeta;
        case 4: return lp.rigid_pole_rad_s;
        default: return m.resonance.omega_rad_s / m.antiresonance.omega_rad_s;
      }
    };
  };
  const Mode& m = out.model.modes.front();
  out.mode.resonance_omega = delta(m.resonance.omega_rad_s, gradient(t, modal(2)), c);
  out.mode.resonance_zeta = delta(m.resonance.zeta, gradient(t, modal(3)), c);
  out.rigid_pole_rad_s = delta(out.model.rigid_pole_rad_s, gradient(t, modal(4)), c);
  if (load) {
    out.mode.antiresonance_omega = out.mode.antiresonance_zeta = out.resonance_ratio = {kNan, kNan};
    return;
  }
  out.mode.antiresonance_omega = delta(m.antiresonance.omega_rad_s, gradient(t, modal(0)), c);
  out.mode.antiresonance_zeta = delta(m.antiresonance.zeta, gradient(t, modal(1)), c);
  out.resonance_ratio = delta(m.resonance.omega_rad_s / m.antiresonance.omega_rad_s, gradient(t, modal(5)), c);
}

/// The points the linear fit used (valid, not left out as outliers), with their weights; empty with
/// `why` set when a point carries no excitation amplitude.
std::vector<Point> fitted_points(const core::FrequencyResponse& response, const FitReport& linear, OutputKind output,
                                 std::vector<double>& amplitudes, bool& known_std, std::string& why) {
  std::vector<const core::FrequencyPoint*> used;
  for (const core::FrequencyPoint& q : response.points) {
    const bool left_out = std::any_of(linear.left_out_hz.begin(), linear.left_out_hz.end(),
                                      [&](double hz) { return hz == q.freq_hz; });
    if (q.valid && !left_out) used.push_back(&q);
  }
  known_std = !used.empty() && std::all_of(used.begin(), used.end(), [](const auto* q) { return q->std_dev > 0.0; });
  std::vector<Point> points;
  for (const core::FrequencyPoint* q : used) {
    const double v = velocity_of(*q, output);
    if (!(q->amplitude > 0.0) || !(v > 0.0) || !std::isfinite(v)) {
      why = "Coulomb friction not fitted: the point at " + std::to_string(q->freq_hz) +
            " Hz carries no excitation amplitude (a swept-sine measurement records it per point)";
      return {};
    }
    const double w = detail::log_residual_weight(*q, response.quality_kind, known_std);
    points.push_back({kTwoPi * q->freq_hz, std::log(q->value), v, w, w, w});
    amplitudes.push_back(q->amplitude);
  }
  return points;
}

/// The chain the linear fit describes, without friction: its physical parameters on the motor
/// side; on the load side the total inertia 1/K' and the resonance, split by `motor_fraction`
/// (ωp² = k J/(Jm Jl), 2ζp ωp = bs J/(Jm Jl)). Empty with `why` when there is none.
std::optional<ChainParameters> linear_chain(const FitReport& linear, double motor_fraction, std::string& why) {
  const PlantModel& lin = linear.result.model;
  if (lin.sensor == SensorSide::kMotor) {
    const auto& start = linear.result.physical.parameters;
    if (!start) {
      why = "Coulomb friction not fitted: the linear fit has no two-mass parameters (" + linear.result.physical.note + ")";
      return std::nullopt;
    }
    return ChainParameters{start->motor_inertia.value, start->load_inertia.value, start->stiffness.value,
                           start->damping.value, 0.0, 0.0, 0.0};
  }
  if (lin.modes.size() != 1 || !(lin.gain > 0.0)) {
    why = "Coulomb friction not fitted: the load-side fit needs one mode and a positive gain (it has " +
          std::to_string(lin.modes.size()) + " mode(s))";
    return std::nullopt;
  }
  const double total = (lin.lag_pole_rad_s ? *lin.lag_pole_rad_s : 1.0) / lin.gain;
  const double jm = motor_fraction * total, jl = (1.0 - motor_fraction) * total, mu = jm * jl / total;
  const ModalPair& res = lin.modes.front().resonance;
  return ChainParameters{jm, jl, res.omega_rad_s * res.omega_rad_s * mu, 2.0 * res.zeta * res.omega_rad_s * mu, 0.0, 0.0, 0.0};
}

}  // namespace

std::complex<double> coulomb_two_mass_response(double omega_rad_s, double motor_velocity_amplitude, double jm, double jl,
                                               double k, double bs, double bv, double mm, double ml,
                                               const PlantModel& linear_model) {
  return detail::chain_response(omega_rad_s, motor_velocity_amplitude, {jm, jl, k, bs, bv, mm, ml}, linear_model,
                                SensorSide::kMotor);
}

std::complex<double> coulomb_two_mass_load_response(double omega_rad_s, double load_velocity_amplitude, double jm, double jl,
                                                    double k, double bs, double bv, double mm, double ml,
                                                    const PlantModel& linear_model) {
  return detail::chain_response(omega_rad_s, load_velocity_amplitude, {jm, jl, k, bs, bv, mm, ml}, linear_model,
                                SensorSide::kLoad);
}

CoulombFit fit_coulomb_friction(const core::FrequencyResponse& response, const FitReport& linear, const FitOptions& options) {
  CoulombFit out;
  const PlantModel& lin = linear.result.model;
  const std::optional<ChainParameters> start = linear_chain(linear, 0.5, out.note);
  if (!start) return out;
  std::vector<double> amplitudes;
  bool known_std = false;
  std::vector<Point> points = fitted_points(response, linear, lin.output, amplitudes, known_std, out.note);
  if (!out.note.empty()) return out;
  const std::size_t m = points.size();
  const Layout layout(lin);
  const bool load = lin.sensor == SensorSide::kLoad;
  const bool fixed_integrator = options.rigid == RigidKind::kIntegrator;
  std::vector<Eigen::Index> fixed;
  if (fixed_integrator) fixed.push_back(kBv);
  const auto free_parameters = static_cast<std::size_t>(layout.size) - fixed.size();
  if (2 * m <= free_parameters) {
    out.note = "Coulomb friction not fitted: " + std::to_string(m) + " points are too few for " +
               std::to_string(free_parameters) + " parameters";
    return out;
  }
  const double lowest_amplitude = amplitudes.front();
  std::nth_element(amplitudes.begin(), amplitudes.begin() + static_cast<std::ptrdiff_t>(m / 2), amplitudes.end());
  const double jm0 = start->jm, jl0 = start->jl, k0 = start->k;
  const double wz0 = std::sqrt(k0 / jl0);
  const Context ctx{jm0 * wz0, amplitudes[m / 2], 1.0 / wz0, lin, lin.sensor};

  core::LmOptions lo;
  lo.numeric_jacobian = true;
  lo.record_history = false;
  lo.max_iterations = std::max(options.max_iterations, 400);
  lo.covariance_scale = known_std ? core::LmCovarianceScale::kKnown : core::LmCovarianceScale::kEstimated;
  lo.lower = Eigen::VectorXd::Constant(layout.size, -std::numeric_limits<double>::infinity());
  lo.upper = Eigen::VectorXd::Constant(layout.size, std::numeric_limits<double>::infinity());
  if (layout.delay >= 0) (*lo.lower)[layout.delay] = 0.0;
  (*lo.lower)[kBv] = 0.0;
  (*lo.lower)[kMm] = 0.0;
  (*lo.lower)[kMl] = 0.0;
  if (fixed_integrator) (*lo.upper)[kBv] = 0.0;
  if (load) {
    // The share within [0.007, 0.993]: a chain whose one mass vanishes is not a two-mass chain.
    (*lo.lower)[kJl] = -5.0;
    (*lo.upper)[kJl] = 5.0;
  }
  const auto f = [&](const Eigen::VectorXd& t, Eigen::VectorXd& res, Eigen::MatrixXd*) {
    return residuals(t, points, ctx, res);
  };

  // Starts: the linear fit's parameters read without friction (its rigid pole as viscous damping),
  // and the same with that damping read as Coulomb friction, split evenly between the masses or all
  // on the load: at the lowest point the describing function 4M/(π|V|) equals the viscous
  // a·(Jm + Jl). An integrator fit has no such damping to read; its friction starts at half the
  // lowest point's excitation amplitude, where friction shows most.
  const double a = lin.rigid == RigidKind::kRealPole ? lin.rigid_pole_rad_s : 0.0;
  const double bv0 = fixed_integrator ? 0.0 : a * (jm0 + jl0);
  const double m0 = a > 0.0 ? kPi * points.front().velocity * a * (jm0 + jl0) / 4.0 : 0.5 * lowest_amplitude;
  const std::array<std::array<double, 3>, 3> starts{{{bv0, 0.0, 0.0}, {0.0, 0.5 * m0, 0.5 * m0}, {0.0, 0.0, m0}}};
  core::LmResult best;
  best.cost = std::numeric_limits<double>::infinity();
  for (const auto& [bv, mm, ml] : starts) {
    Eigen::VectorXd t(layout.size);
    t.head<kCount>() << std::log(load ? jm0 + jl0 : jm0), load ? 0.0 : std::log(jl0), std::log(k0),
        std::log(std::max(start->bs, 1e-6 * jm0 * wz0)), bv / ctx.viscous, mm / ctx.torque, ml / ctx.torque;
    // A lag the linear fit pushed far above the data (it traded it for the friction's phase) has
    // no gradient left there; it starts at most a decade above the highest point.
    if (layout.lag >= 0) t[layout.lag] = std::log(std::min(*lin.lag_pole_rad_s, 10.0 * points.back().omega));
    if (layout.delay >= 0) t[layout.delay] = *lin.delay_s / ctx.time;
    core::LmResult run = core::levenberg_marquardt(f, t, 2 * m, lo);
    if (better(run, best)) best = std::move(run);
  }
  out.points = m;
  if (!std::isfinite(best.cost) || !best.converged()) {
    out.note = "Coulomb friction fit did not converge: " + (std::isfinite(best.cost) ? best.message : "no valid start");
    return out;
  }
  // Second pass with the errors-in-variables weights of the first solution (kept when it fails).
  const std::vector<Point> first_weights = points;
  errors_in_variables(best.parameters, ctx, points);
  core::LmResult second = core::levenberg_marquardt(f, best.parameters, 2 * m, lo);
  if (second.converged())
    best = std::move(second);
  else
    points = first_weights;
  out.fitted = true;
  out.iterations = best.iterations;
  out.message = best.message;
  out.cost = best.cost;
  out.weighting = known_std ? "std_dev" : "log-relative";
  out.rms_log_error = unweighted_rms(best.residual, points);
  out.linear_rms_log_error = linear.result.rms_log_error;
  Eigen::MatrixXd covariance = free_covariance(best, known_std, fixed);
  std::string held;
  const bool share_held = load && !covariance.allFinite();
  if (share_held) {
    // Friction too small to tell the split (a singular Jacobian): the share stays where LM left it
    // and is no parameter; its std and those of the inertias are then unknown (NaN), not 0.
    fixed.push_back(kJl);
    covariance = free_covariance(best, known_std, fixed);
    held = "; the motor's share of the inertia is not seen (too little friction) and is held at " +
           std::to_string(motor_share(best.parameters)).substr(0, 5);
  }
  const double dof = 2.0 * static_cast<double>(m) - static_cast<double>(layout.size) + static_cast<double>(fixed.size());
  out.sigma2 = known_std ? 1.0 : best.residual.squaredNorm() / dof;
  const detail::MisfitScale misfit = detail::misfit_scale(best.residual, dof, known_std);
  out.uncertainty_scale = misfit.factor;
  out.uncertainty_note = misfit.note;
  fill_estimates(out, best.parameters, covariance * misfit.factor, ctx, options.rigid);
  if (share_held) out.motor_share.std = out.motor_inertia.std = out.load_inertia.std = kNan;
  out.note = std::string("two-mass model with Coulomb friction on motor and load (describing functions at each point's "
                         "measured amplitude") +
             (load ? ", seen from the load encoder" : "") + "), " + std::to_string(m) + " points" + held;
  return out;
}

FitReport with_friction_model(FitReport linear, const CoulombFit& f) {
  if (!f.fitted) return linear;
  FitResult& r = linear.result;
  const bool load = f.model.sensor == SensorSide::kLoad;
  r.model = f.model;
  r.gain = f.gain;
  r.rigid_pole_rad_s = f.model.rigid == RigidKind::kRealPole ? f.rigid_pole_rad_s : Estimate{0.0, 0.0};
  r.mode_estimates = {f.mode};
  r.parameter_names = {load ? "ln_total_inertia" : "ln_motor_inertia", load ? "logit_motor_share" : "ln_load_inertia",
                       load ? "ln_stiffness_at_even_share" : "ln_stiffness", load ? "ln_shaft_damping_at_even_share" : "ln_shaft_damping", "viscous_damping_scaled", "motor_coulomb_scaled",
                       "load_coulomb_scaled"};
  if (f.model.lag_pole_rad_s) r.parameter_names.emplace_back("ln_lag_pole");
  if (f.model.delay_s) r.parameter_names.emplace_back("delay_scaled");
  r.theta = f.theta;
  r.covariance = f.covariance;
  r.parameters = static_cast<std::size_t>(f.theta.size());
  r.points = f.points;
  r.lag_pole_rad_s = f.lag_pole_rad_s;
  r.delay_s = f.delay_s;
  r.rms_log_error = f.rms_log_error;
  r.cost = f.cost;
  r.sigma2 = f.sigma2;
  r.weighting = f.weighting;
  r.uncertainty_scale = f.uncertainty_scale;
  r.uncertainty_note = f.uncertainty_note;
  r.iterations = f.iterations;
  r.initialization += ", then with Coulomb friction from the linear fit";
  r.message += "; then with Coulomb friction: " + f.message;
  if (load) {
    r.physical.parameters.reset();
    r.physical.note = "no two-mass parameters written from a load-side response (the model has no antiresonance); the "
                      "fit with Coulomb friction gives the total inertia " + std::to_string(f.total_inertia.value) +
                      " and the motor's share " + std::to_string(f.motor_share.value);
    return linear;
  }
  TwoMassParameters p;
  p.motor_inertia = f.motor_inertia;
  p.load_inertia = f.load_inertia;
  p.stiffness = f.stiffness;
  p.damping = f.shaft_damping;
  p.resonance_ratio = f.resonance_ratio;
  const Mode& m = f.model.modes.front();
  const double ratio = f.resonance_ratio.value;
  p.damping_consistency = m.resonance.zeta / (ratio * m.antiresonance.zeta);
  r.physical.parameters = p;
  r.physical.note = "two-mass parameters of the fit with Coulomb friction (viscous damping at the motor " +
                    std::to_string(f.viscous_damping.value) + ")";
  return linear;
}

std::complex<double> coulomb_response_at(const CoulombFit& f, const core::FrequencyPoint& point) {
  const double v = velocity_of(point, f.model.output);
  if (!f.fitted || !(v > 0.0) || !std::isfinite(v)) return {kNan, 0.0};
  return detail::chain_response(kTwoPi * point.freq_hz, v,
                                {f.motor_inertia.value, f.load_inertia.value, f.stiffness.value, f.shaft_damping.value,
                                 f.viscous_damping.value, f.motor_coulomb.value, f.load_coulomb.value},
                                f.model, f.model.sensor);
}

}  // namespace servotwin::fit
