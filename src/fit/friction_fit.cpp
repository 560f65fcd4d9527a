#include "servotwin/fit/friction_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <vector>

#include "servotwin/core/levenberg_marquardt.hpp"
#include "servotwin/core/polynomial.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2.0 * kPi;

/// θ = (ln Jm, ln Jl, ln k, ln bs, bv/bv_ref, Mm/T_ref, Ml/T_ref[, ln p][, T ωz]): logs keep the
/// positive quantities positive; the three that may be 0 are scaled to order one (T_ref the median
/// excitation amplitude, bv_ref = Jm ωz of the start) so that LM's central differences and box
/// bounds act on comparable numbers. The lag pole p and the delay T, when the linear fit has them,
/// are fitted again: friction bends the linear fit's phase, and with it its lag.
enum Index : Eigen::Index { kJm, kJl, kK, kBs, kBv, kMm, kMl, kCount };

struct Scales {
  double viscous = 1.0;  ///< bv_ref
  double torque = 1.0;   ///< T_ref
  double time = 1.0;     ///< 1/ωz of the start, the delay's unit
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
PlantModel actuator_of(const Eigen::VectorXd& t, const PlantModel& linear, const Scales& s) {
  PlantModel m;
  m.output = linear.output;
  const Layout l(linear);
  if (l.lag >= 0) m.lag_pole_rad_s = std::exp(t[l.lag]);
  if (l.delay >= 0) m.delay_s = t[l.delay] * s.time;
  return m;
}

struct Point {
  double omega = 0.0;
  Complex log_meas;
  double motor_velocity = 0.0;  ///< |Vm| = |P|·T (velocity output) or ω|P|·T (position output)
};

struct Physical {
  double jm, jl, k, bs, bv, mm, ml;
};

Physical physical_of(const Eigen::VectorXd& t, const Scales& s) {
  return {std::exp(t[kJm]), std::exp(t[kJl]), std::exp(t[kK]), std::exp(t[kBs]), t[kBv] * s.viscous, t[kMm] * s.torque,
          t[kMl] * s.torque};
}

/// The linear fit's lag p/(s + p) (unity at DC: PlantModel's 1/(s + p) with the gain's factor p
/// moved into 1/Jm) and delay, at s = jω.
Complex actuator(const PlantModel& m, double omega) {
  const Complex s(0.0, omega);
  Complex a = 1.0;
  if (m.lag_pole_rad_s) a *= *m.lag_pole_rad_s / (s + *m.lag_pole_rad_s);
  if (m.delay_s) a *= std::polar(1.0, -omega * *m.delay_s);
  return a;
}

/// The load's velocity over the motor's, G = Z/(Jl s + cl + Z), with cl = 4Ml/(π|Vl|) and
/// |Vl| = |G|·|Vm|. Writing Jl s + Z = bs + jX (X = Jl ω − k/ω) and c = 4Ml/π, |Vl| = x solves
/// x²((bs + c/x)² + X²) = |Vm|²|Z|², i.e. (bs² + X²)x² + 2 bs c x + c² − |Vm|²|Z|² = 0, whose
/// positive root exists when |Vm||Z| > c; otherwise the load sticks (G = 0).
Complex load_over_motor(double omega, double vm, const Physical& p) {
  const Complex z(p.bs, -p.k / omega);
  const double x_reactance = p.jl * omega - p.k / omega;
  const double c = 4.0 * p.ml / kPi;
  if (c == 0.0) return z / (Complex(0.0, p.jl * omega) + z);
  const double drive = vm * std::abs(z);
  if (drive <= std::abs(c) && c > 0.0) return 0.0;
  const double a2 = p.bs * p.bs + x_reactance * x_reactance;
  const double disc = p.bs * p.bs * c * c - a2 * (c * c - drive * drive);
  const double x = (-p.bs * c + std::sqrt(std::max(disc, 0.0))) / a2;
  if (!(x > 0.0)) return 0.0;
  return z / (Complex(p.bs + c / x, x_reactance));
}

Complex model_response(double omega, double vm, const Physical& p, const PlantModel& linear) {
  const Complex s(0.0, omega);
  const Complex z(p.bs, -p.k / omega);
  const Complex g = load_over_motor(omega, vm, p);
  const Complex impedance = p.jm * s + p.bv + 4.0 * p.mm / (kPi * vm) + z * (1.0 - g);
  Complex r = actuator(linear, omega) / impedance;
  if (linear.output == OutputKind::kPosition) r /= s;
  return r;
}

bool residuals(const Eigen::VectorXd& t, const std::vector<Point>& points, const Scales& scales, const PlantModel& linear,
               Eigen::VectorXd& r) {
  if ((t.head<4>().array().abs() > 700.0).any()) return false;
  const Physical p = physical_of(t, scales);
  const PlantModel act = actuator_of(t, linear, scales);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Complex m = model_response(points[k].omega, points[k].motor_velocity, p, act);
    if (!std::isfinite(m.real()) || !std::isfinite(m.imag()) || m == 0.0) return false;
    const Complex e = std::log(m) - points[k].log_meas;
    r[static_cast<Eigen::Index>(2 * k)] = e.real();
    r[static_cast<Eigen::Index>(2 * k + 1)] = std::remainder(e.imag(), kTwoPi);
  }
  return true;
}

double rms(const Eigen::VectorXd& r) { return std::sqrt(r.squaredNorm() / (0.5 * static_cast<double>(r.size()))); }

/// The linear part's modal model: zeros of Jl s² + bs s + k, poles of
/// (Jm s + bv)(Jl s² + bs s + k) + Jl s (bs s + k) (motor velocity over torque, C3.12), gain
/// 1/Jm times the lag's p.
PlantModel linear_part(const Physical& p, const PlantModel& linear, RigidKind rigid) {
  PlantModel m;
  m.output = linear.output;
  m.lag_pole_rad_s = linear.lag_pole_rad_s;
  m.delay_s = linear.delay_s;
  m.gain = (linear.lag_pole_rad_s ? *linear.lag_pole_rad_s : 1.0) / p.jm;
  const double wz = std::sqrt(p.k / p.jl);
  ModalPair zero{wz, p.bs / (2.0 * std::sqrt(p.k * p.jl))};
  // Monic cubic s³ + c2 s² + c1 s + c0 over Jm Jl.
  const double jj = p.jm * p.jl;
  const core::Polynomial den{1.0, ((p.jm + p.jl) * p.bs + p.bv * p.jl) / jj, ((p.jm + p.jl) * p.k + p.bv * p.bs) / jj,
                             p.bv * p.k / jj};
  // The rigid pole is the real root nearest 0 (exactly 0 when bv = 0); the other two, a complex
  // pair or (overdamped) two real roots, form the resonance: ω² = their product, 2ζω = −their sum.
  std::vector<Complex> roots = den.roots();
  std::sort(roots.begin(), roots.end(), [](Complex x, Complex y) { return std::abs(x) < std::abs(y); });
  if (roots[0].imag() != 0.0) std::swap(roots[0], roots[2]);  // a pair below the real root: keep the real one rigid
  const double omega_n = std::sqrt((roots[1] * roots[2]).real());
  const double zeta_n = -(roots[1] + roots[2]).real() / (2.0 * omega_n);
  m.rigid = rigid == RigidKind::kIntegrator || p.bv == 0.0 ? RigidKind::kIntegrator : RigidKind::kRealPole;
  m.rigid_pole_rad_s = m.rigid == RigidKind::kRealPole ? -roots[0].real() : 0.0;
  m.modes = {{zero, {omega_n, zeta_n}}};
  return m;
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

void fill_estimates(CoulombFit& out, const core::LmResult& lm, const Scales& scales, const PlantModel& linear,
                    RigidKind rigid) {
  const Eigen::VectorXd& t = lm.parameters;
  const Eigen::MatrixXd& c = lm.covariance;
  const Physical p = physical_of(t, scales);
  auto log_param = [&](Index i) {
    return Estimate{std::exp(t[i]), std::exp(t[i]) * std::sqrt(std::max(0.0, c(i, i)))};
  };
  auto scaled_param = [&](Index i, double scale) {
    return Estimate{t[i] * scale, scale * std::sqrt(std::max(0.0, c(i, i)))};
  };
  out.motor_inertia = log_param(kJm);
  out.load_inertia = log_param(kJl);
  out.stiffness = log_param(kK);
  out.shaft_damping = log_param(kBs);
  out.viscous_damping = scaled_param(kBv, scales.viscous);
  out.motor_coulomb = scaled_param(kMm, scales.torque);
  out.load_coulomb = scaled_param(kMl, scales.torque);
  out.model = linear_part(p, actuator_of(t, linear, scales), rigid);
  const Layout l(linear);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.lag_pole_rad_s = l.lag >= 0 ? log_param(static_cast<Index>(l.lag)) : Estimate{nan, nan};
  out.delay_s = l.delay >= 0 ? scaled_param(static_cast<Index>(l.delay), scales.time) : Estimate{nan, nan};
  out.theta = t;
  out.covariance = c;
  auto modal = [&](int which) {
    return [&, which](const Eigen::VectorXd& x) {
      const PlantModel lp = linear_part(physical_of(x, scales), actuator_of(x, linear, scales), rigid);
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
  out.mode = {delta(m.antiresonance.omega_rad_s, gradient(t, modal(0)), c), delta(m.antiresonance.zeta, gradient(t, modal(1)), c),
              delta(m.resonance.omega_rad_s, gradient(t, modal(2)), c), delta(m.resonance.zeta, gradient(t, modal(3)), c)};
  out.rigid_pole_rad_s = delta(out.model.rigid_pole_rad_s, gradient(t, modal(4)), c);
  out.resonance_ratio = delta(m.resonance.omega_rad_s / m.antiresonance.omega_rad_s, gradient(t, modal(5)), c);
}

}  // namespace

std::complex<double> coulomb_two_mass_response(double omega_rad_s, double motor_velocity_amplitude, double jm, double jl,
                                               double k, double bs, double bv, double mm, double ml,
                                               const PlantModel& linear_model) {
  return model_response(omega_rad_s, motor_velocity_amplitude, {jm, jl, k, bs, bv, mm, ml}, linear_model);
}

CoulombFit fit_coulomb_friction(const core::FrequencyResponse& response, const FitReport& linear, const FitOptions& options) {
  CoulombFit out;
  const auto& start = linear.result.physical.parameters;
  if (!start) {
    out.note = "Coulomb friction not fitted: the linear fit has no two-mass parameters (" + linear.result.physical.note + ")";
    return out;
  }
  const PlantModel& lin = linear.result.model;
  std::vector<Point> points;
  std::vector<double> amplitudes;
  for (const core::FrequencyPoint& q : response.points) {
    if (!q.valid) continue;
    const double omega = kTwoPi * q.freq_hz;
    const double vm = std::abs(q.value) * q.amplitude * (lin.output == OutputKind::kPosition ? omega : 1.0);
    if (!(q.amplitude > 0.0) || !(vm > 0.0) || !std::isfinite(vm)) {
      out.note = "Coulomb friction not fitted: the point at " + std::to_string(q.freq_hz) +
                 " Hz carries no excitation amplitude (a swept-sine measurement records it per point)";
      return out;
    }
    points.push_back({omega, std::log(q.value), vm});
    amplitudes.push_back(q.amplitude);
  }
  const std::size_t m = points.size();
  const Layout layout(lin);
  if (2 * m <= static_cast<std::size_t>(layout.size)) {
    out.note = "Coulomb friction not fitted: " + std::to_string(m) + " valid points are too few for " +
               std::to_string(layout.size) + " parameters";
    return out;
  }
  std::nth_element(amplitudes.begin(), amplitudes.begin() + static_cast<std::ptrdiff_t>(m / 2), amplitudes.end());
  const double jm0 = start->motor_inertia.value, jl0 = start->load_inertia.value, k0 = start->stiffness.value;
  const double wz0 = std::sqrt(k0 / jl0);
  Scales scales{jm0 * wz0, amplitudes[m / 2], 1.0 / wz0};

  Eigen::VectorXd r(static_cast<Eigen::Index>(2 * m));
  const bool fixed_integrator = options.rigid == RigidKind::kIntegrator;
  core::LmOptions lo;
  lo.numeric_jacobian = true;
  lo.record_history = false;
  lo.max_iterations = std::max(options.max_iterations, 400);
  lo.lower = Eigen::VectorXd::Constant(layout.size, -std::numeric_limits<double>::infinity());
  lo.upper = Eigen::VectorXd::Constant(layout.size, std::numeric_limits<double>::infinity());
  if (layout.delay >= 0) (*lo.lower)[layout.delay] = 0.0;
  (*lo.lower)[kBv] = 0.0;
  (*lo.lower)[kMm] = 0.0;
  (*lo.lower)[kMl] = 0.0;
  if (fixed_integrator) (*lo.upper)[kBv] = 0.0;
  const auto f = [&](const Eigen::VectorXd& t, Eigen::VectorXd& res, Eigen::MatrixXd*) {
    return residuals(t, points, scales, lin, res);
  };

  // Starts: the linear fit's parameters read without friction (its rigid pole as viscous damping),
  // and the same with that damping read as Coulomb friction split evenly between the masses: at
  // the lowest point the describing function 4M/(π|V|) equals the viscous a·(Jm + Jl).
  const double a = lin.rigid == RigidKind::kRealPole ? lin.rigid_pole_rad_s : 0.0;
  const double bv0 = fixed_integrator ? 0.0 : a * (jm0 + jl0);
  const double m0 = kPi * points.front().motor_velocity * a * (jm0 + jl0) / 4.0;
  std::array<std::array<double, 3>, 3> starts{{{bv0, 0.0, 0.0}, {0.0, 0.5 * m0, 0.5 * m0}, {0.0, 0.0, m0}}};
  core::LmResult best;
  best.cost = std::numeric_limits<double>::infinity();
  for (const auto& [bv, mm, ml] : starts) {
    Eigen::VectorXd t(layout.size);
    t.head<kCount>() << std::log(jm0), std::log(jl0), std::log(k0),
        std::log(std::max(start->damping.value, 1e-6 * jm0 * wz0)), bv / scales.viscous, mm / scales.torque,
        ml / scales.torque;
    if (layout.lag >= 0) t[layout.lag] = std::log(*lin.lag_pole_rad_s);
    if (layout.delay >= 0) t[layout.delay] = *lin.delay_s / scales.time;
    core::LmResult run = core::levenberg_marquardt(f, t, 2 * m, lo);
    if (run.status != core::LmStatus::kInvalidStart && run.cost < best.cost) best = std::move(run);
  }
  out.points = m;
  if (!std::isfinite(best.cost) || !best.converged()) {
    out.note = "Coulomb friction fit did not converge: " + (std::isfinite(best.cost) ? best.message : "no valid start");
    return out;
  }
  out.fitted = true;
  out.iterations = best.iterations;
  out.message = best.message;
  out.rms_log_error = rms(best.residual);
  out.linear_rms_log_error = linear.result.rms_log_error;
  fill_estimates(out, best, scales, lin, options.rigid);
  out.note = "two-mass model with Coulomb friction on motor and load (describing functions at each point's "
             "measured amplitude), " + std::to_string(m) + " points";
  return out;
}

FitReport with_friction_model(FitReport linear, const CoulombFit& f) {
  if (!f.fitted) return linear;
  FitResult& r = linear.result;
  r.model = f.model;
  // K = p/Jm: the same relative standard deviation as Jm.
  r.gain = {f.model.gain, f.model.gain * f.motor_inertia.std / f.motor_inertia.value};
  r.rigid_pole_rad_s = f.model.rigid == RigidKind::kRealPole ? f.rigid_pole_rad_s : Estimate{0.0, 0.0};
  r.mode_estimates = {f.mode};
  r.parameter_names = {"ln_motor_inertia", "ln_load_inertia", "ln_stiffness", "ln_shaft_damping",
                       "viscous_damping_scaled", "motor_coulomb_scaled", "load_coulomb_scaled"};
  if (f.model.lag_pole_rad_s) r.parameter_names.emplace_back("ln_lag_pole");
  if (f.model.delay_s) r.parameter_names.emplace_back("delay_scaled");
  r.theta = f.theta;
  r.covariance = f.covariance;
  r.parameters = static_cast<std::size_t>(f.theta.size());
  r.lag_pole_rad_s = f.lag_pole_rad_s;
  r.delay_s = f.delay_s;
  r.rms_log_error = f.rms_log_error;
  r.iterations = f.iterations;
  r.message += "; then with Coulomb friction: " + f.message;
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

}  // namespace servotwin::fit
