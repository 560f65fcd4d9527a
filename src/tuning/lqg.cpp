#include "servotwin/tuning/lqg.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "checks.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/core/norms.hpp"
#include "servotwin/core/riccati.hpp"
#include "servotwin/core/transfer_function.hpp"

namespace servotwin::tuning {

namespace {

using Complex = std::complex<double>;
using Matrix = Eigen::MatrixXd;

/// A controller pole counts as stable within this margin of the imaginary axis (relative to the
/// largest pole): the integrator's pole at 0 is the only one expected there.
constexpr double kImaginaryAxisTolerance = 1e-9;

std::vector<Complex> poles_of(const Matrix& a) { return detail::sorted_poles(a); }

void check_plant(const FrictionTwoMass& p, double r) {
  detail::require_positive(p.stiffness, "stiffness", "a shaft stiffness");
  detail::require_positive(p.load_inertia, "load_inertia", "a load inertia");
  detail::require_ratio(r, "r");
  detail::require_non_negative(p.damping, "damping", "a shaft damping");
  // The friction terms may be negative: the exact realization of a fit that is not passive
  // (two_mass_realization()) is still a valid design model.
  detail::require_finite(p.motor_viscous, "motor_viscous");
  detail::require_finite(p.load_viscous, "load_viscous");
}

/// ρ = kbw/c² with c = r²/2 (C7.13).
double control_weight(double kbw, double r) {
  const double c = r * r / 2.0;
  return kbw / (c * c);
}

/// The regulator gain K = R⁻¹ Bᵀ X of the CARE (scalar input).
Eigen::RowVectorXd regulator(const Matrix& a, const Matrix& b, const Matrix& q, double rho, double& residual) {
  core::CareReport report;
  const Matrix x = core::solve_care(a, b, q, Matrix::Constant(1, 1, rho), &report);
  residual = std::max(residual, report.relative_residual);
  return (b.transpose() * x).row(0) / rho;
}

/// The Kalman gain L = Y Cᵀ V⁻¹ of the filter CARE (one column per measurement).
Matrix estimator(const Matrix& a, const Matrix& c, const Matrix& w, const Matrix& v, double& residual) {
  core::CareReport report;
  const Matrix y = core::solve_care_filter(a, c, w, v, &report);
  residual = std::max(residual, report.relative_residual);
  return y * c.transpose() * v.inverse();
}

/// Plant + compensator closed loop (reference and load torque set to zero): its poles. The
/// compensator's measurement channels u = K_y y carry their own sign: positive feedback.
std::vector<Complex> closed_loop_poles(const core::StateSpace& plant, const core::StateSpace& c) {
  const Eigen::Index m = c.B.cols() - 1;  // measurements: the plant's first m outputs
  const core::StateSpace torque_to_measurement{plant.A, plant.B.col(0), plant.C.topRows(m), plant.D.block(0, 0, m, 1)};
  const core::StateSpace measurement_to_torque{c.A, c.B.rightCols(m), c.C, c.D.rightCols(m)};
  return poles_of(core::feedback(torque_to_measurement, measurement_to_torque, +1).A);
}

/// The estimator's model: the plant's states plus a constant load torque, input Tm, outputs the
/// plant's first `measurements` outputs.
struct EstimatorModel {
  Matrix a, b, c;
};
EstimatorModel estimator_model(const core::StateSpace& p, Eigen::Index measurements = 1) {
  const Eigen::Index n = p.A.rows();
  EstimatorModel e{Matrix::Zero(n + 1, n + 1), Matrix::Zero(n + 1, 1), Matrix::Zero(measurements, n + 1)};
  e.a.topLeftCorner(n, n) = p.A;
  e.a.block(0, n, n, 1) = p.B.col(1);
  e.b.topRows(n) = p.B.col(0);
  e.c.leftCols(n) = p.C.topRows(measurements);
  return e;
}

/// Regulator on the plant's states plus the integral of −y_i (xi' = reference − y_i at run time,
/// i = `integral_output`) and estimator on the plant's states plus a constant load torque (the
/// model's measurements); the design's gains and pole sets. `q` is the diagonal of Q over [plant
/// states, xi]; `w` the process-noise intensity over [plant states, Tl]; `v` the measurement noise's.
LqgDesign regulator_and_estimator(const core::StateSpace& p, const EstimatorModel& e, const Eigen::VectorXd& q,
                                  double rho, const Matrix& w, const Matrix& v, Eigen::Index integral_output = 0) {
  const Eigen::Index n = p.A.rows();
  LqgDesign d;
  Matrix a = Matrix::Zero(n + 1, n + 1);
  a.topLeftCorner(n, n) = p.A;
  a.bottomLeftCorner(1, n) = -p.C.row(integral_output);
  Matrix b = Matrix::Zero(n + 1, 1);
  b.topRows(n) = p.B.col(0);
  d.regulator_gain = regulator(a, b, q.asDiagonal().toDenseMatrix(), rho, d.riccati_residual);
  d.regulator_poles = poles_of(a - b * d.regulator_gain);
  d.estimator_gain = estimator(e.a, e.c, w, v, d.riccati_residual);
  d.estimator_poles = poles_of(e.a - d.estimator_gain * e.c);
  return d;
}

/// The compensator with states [x̂ (plant + Tl), xi], inputs [reference, y (the model's
/// measurements)], output
///   u = −kx x̂ − K_xi xi − ky y₁ + kref·reference,
/// x̂' = Ae x̂ + Be u + L (y − Ce x̂), xi' = reference − y_i (i = `integral_output`); its poles and
/// the closed loop's.
void finish(LqgDesign& d, const core::StateSpace& p, const EstimatorModel& e, const Eigen::RowVectorXd& kx, double ky,
            double kref, Eigen::Index integral_output = 0) {
  const Eigen::Index ne = p.A.rows() + 1;
  const Matrix& ae = e.a;
  const Matrix& be = e.b;
  const Matrix& ce = e.c;
  const double k_xi = d.regulator_gain(ne - 1);
  core::StateSpace& c = d.compensator;
  c.A = Matrix::Zero(ne + 1, ne + 1);
  c.A.topLeftCorner(ne, ne) = ae - be * kx - d.estimator_gain * ce;
  c.A.block(0, ne, ne, 1) = -be * k_xi;
  const Eigen::Index m = ce.rows();
  c.B = Matrix::Zero(ne + 1, 1 + m);
  c.B.block(0, 0, ne, 1) = be * kref;
  c.B.block(0, 1, ne, m) = d.estimator_gain;
  c.B.block(0, 1, ne, 1) -= be * ky;
  c.B(ne, 0) = 1.0;
  c.B(ne, 1 + integral_output) = -1.0;
  c.C = Matrix::Zero(1, ne + 1);
  c.C.leftCols(ne) = -kx;
  c.C(0, ne) = -k_xi;
  c.D = Matrix::Zero(1, 1 + m);
  c.D(0, 0) = kref;
  c.D(0, 1) = -ky;
  d.controller_poles = poles_of(c.A);
  d.controller_stable = stable_except_integrator(d.controller_poles);
  d.closed_loop_poles = closed_loop_poles(p, c);
}

void check_velocity_options(const VelocityLqgOptions& o) {
  detail::require_positive(o.kbw, "kbw", "the LQG bandwidth knob");
  detail::require_positive(o.measurement_noise, "measurement_noise", "a measurement-noise intensity");
  detail::require_non_negative(o.q_load_velocity, "q_load_velocity");
  detail::require_non_negative(o.q_integral, "q_integral");
  detail::require_non_negative(o.noise_motor, "noise_motor");
  detail::require_non_negative(o.noise_load_torque, "noise_load_torque");
  detail::require_non_negative(o.feedforward, "feedforward");
}

/// The velocity estimator's process noise: into ωm and the load torque.
Matrix velocity_process_noise(const VelocityLqgOptions& o) {
  Matrix w = Matrix::Zero(4, 4);
  w(0, 0) = o.noise_motor;
  w(3, 3) = o.noise_load_torque;
  return w;
}


}  // namespace

core::StateSpace two_mass_state_space(const FrictionTwoMass& p, bool position) {
  const double il = p.load_inertia, k = p.stiffness, b = p.damping, bm = p.motor_viscous, bl = p.load_viscous;
  core::StateSpace s;
  if (!position) {
    s.A.resize(3, 3);
    s.A << -(b + bm), b, -1.0,  //
        b / il, -(b + bl) / il, 1.0 / il,  //
        k, -k, 0.0;
    s.B.setZero(3, 2);
    s.B(0, 0) = 1.0;
    s.B(1, 1) = -1.0 / il;
    s.C.setZero(2, 3);
    s.C(0, 0) = 1.0;
    s.C(1, 1) = 1.0;
  } else {
    s.A.resize(4, 4);
    s.A << 0.0, 1.0, 0.0, 0.0,  //
        -k, -(b + bm), k, b,  //
        0.0, 0.0, 0.0, 1.0,  //
        k / il, b / il, -k / il, -(b + bl) / il;
    s.B.setZero(4, 2);
    s.B(1, 0) = 1.0;
    s.B(3, 1) = -1.0 / il;
    s.C.setZero(2, 4);
    s.C(0, 0) = 1.0;
    s.C(1, 2) = 1.0;
  }
  s.D.setZero(2, 2);
  return s;
}

LqgDesign velocity_lqg(const FrictionTwoMass& plant, double r, const VelocityLqgOptions& o) {
  return velocity_lqg(plant, {}, r, o);
}

LqgDesign velocity_lqg(const FrictionTwoMass& plant, std::span<const fit::Mode> higher_modes, double r,
                       const VelocityLqgOptions& o) {
  check_plant(plant, r);
  check_velocity_options(o);
  const core::StateSpace p = two_mass_state_space_with_modes(plant, higher_modes);
  const Eigen::Index n = p.A.rows();
  const double rho = control_weight(o.kbw, r);
  // Q over [ωm, ωl, Ts, modes…, xi] and W over [ωm, ωl, Ts, modes…, Tl]: the modes get neither.
  if (n < 3) throw std::logic_error("velocity_lqg: the design model lost its two-mass states");
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n + 1);
  q(1) = o.q_load_velocity;
  q(2) = rho;
  q(n) = o.q_integral;
  Matrix w = Matrix::Zero(n + 1, n + 1);
  w(0, 0) = o.noise_motor;
  w(n, n) = o.noise_load_torque;
  const EstimatorModel e = estimator_model(p);
  LqgDesign d = regulator_and_estimator(p, e, q, rho, w, Matrix::Constant(1, 1, o.measurement_noise));
  // u = −K x̂ − K_xi xi + kff ω* (K₁ on the measurement with raw_motor_velocity).
  Eigen::RowVectorXd kx = Eigen::RowVectorXd::Zero(n + 1);
  kx.head(n) = d.regulator_gain.head(n);
  double ky = 0.0;
  if (o.raw_motor_velocity) std::swap(ky, kx(0));
  finish(d, p, e, kx, ky, o.feedforward);
  return d;
}

core::StateSpace two_mass_state_space_with_modes(const FrictionTwoMass& plant, std::span<const fit::Mode> higher_modes) {
  core::StateSpace out = two_mass_state_space(plant, false);
  for (std::size_t i = 0; i < higher_modes.size(); ++i) {
    const fit::Mode& m = higher_modes[i];
    const std::string field = "higher_modes[" + std::to_string(i) + "]";
    detail::require_positive(m.antiresonance.omega_rad_s, field + ".antiresonance.omega_rad_s", "a frequency");
    detail::require_positive(m.resonance.omega_rad_s, field + ".resonance.omega_rad_s", "a frequency");
    detail::require_non_negative(m.antiresonance.zeta, field + ".antiresonance.zeta", "a damping");
    detail::require_non_negative(m.resonance.zeta, field + ".resonance.zeta", "a damping");
    const core::StateSpace f = core::to_state_space(mode_factor(m));
    // The factor's output is the torque the model so far is driven with: Tm' = Cf xf + Df Tm.
    const Eigen::Index n = out.A.rows(), k = f.A.rows();
    core::StateSpace s;
    s.A = Matrix::Zero(n + k, n + k);
    s.A.topLeftCorner(n, n) = out.A;
    s.A.block(0, n, n, k) = out.B.col(0) * f.C;
    s.A.bottomRightCorner(k, k) = f.A;
    s.B = Matrix::Zero(n + k, 2);
    s.B.block(0, 0, n, 1) = out.B.col(0) * f.D(0, 0);
    s.B.block(0, 1, n, 1) = out.B.col(1);
    s.B.block(n, 0, k, 1) = f.B;
    s.C = Matrix::Zero(out.C.rows(), n + k);
    s.C.leftCols(n) = out.C;
    s.D = out.D;
    out = std::move(s);
  }
  return out;
}

LqgDesign load_side_lqg(const FrictionTwoMass& plant, double r, const VelocityLqgOptions& o) {
  check_plant(plant, r);
  check_velocity_options(o);
  if (o.raw_motor_velocity)
    throw core::InputError(core::at_field("raw_motor_velocity"), "not defined for the load-side LQG (C7.17)");
  const core::StateSpace p = two_mass_state_space(plant, false);
  const double rho = control_weight(o.kbw, r);
  const EstimatorModel e = estimator_model(p, 2);  // ωm and ωl measured
  constexpr Eigen::Index kLoadVelocity = 1;
  LqgDesign d = regulator_and_estimator(p, e, Eigen::Vector4d(0.0, o.q_load_velocity, rho, o.q_integral), rho,
                                        velocity_process_noise(o), o.measurement_noise * Matrix::Identity(2, 2),
                                        kLoadVelocity);
  Eigen::RowVectorXd kx = Eigen::RowVectorXd::Zero(4);
  kx.head(3) = d.regulator_gain.head(3);
  finish(d, p, e, kx, 0.0, o.feedforward, kLoadVelocity);
  return d;
}

LqgDesign position_lqg(const FrictionTwoMass& plant, double r, const PositionLqgOptions& o) {
  check_plant(plant, r);
  detail::require_positive(o.kbw, "kbw", "the LQG bandwidth knob");
  detail::require_positive(o.measurement_noise, "measurement_noise", "a measurement-noise intensity");
  detail::require_positive(o.process_noise, "process_noise", "a process-noise intensity");
  for (Eigen::Index i = 0; i < 5; ++i) detail::require_non_negative(o.q(i), "q");

  const core::StateSpace p = two_mass_state_space(plant, true);
  const double rho = control_weight(o.kbw, r);
  const EstimatorModel e = estimator_model(p);
  LqgDesign d =
      regulator_and_estimator(p, e, o.q, rho, o.process_noise * Matrix::Identity(5, 5),
                              Matrix::Constant(1, 1, o.measurement_noise));
  // Error coordinates: u = −K₁(φ̂m − φ*) − K₂ ω̂m − K₃(φ̂l − φ*) − K₄ ω̂l − K₅ xi, so that a step of φ*
  // acts at once and the integral only removes what the load torque leaves.
  Eigen::RowVectorXd kx = Eigen::RowVectorXd::Zero(5);
  kx.head(4) = d.regulator_gain.head(4);
  finish(d, p, e, kx, 0.0, d.regulator_gain(0) + d.regulator_gain(2));
  return d;
}

bool stable_except_integrator(const std::vector<std::complex<double>>& poles) {
  double scale = 1.0;
  for (const Complex p : poles) scale = std::max(scale, std::abs(p));
  bool integrator_seen = false;
  for (const Complex p : poles) {
    if (std::abs(p) <= kImaginaryAxisTolerance * scale && !integrator_seen) {
      integrator_seen = true;  // the integral state of the compensator
      continue;
    }
    if (p.real() >= -kImaginaryAxisTolerance * scale) return false;
  }
  return true;
}

ControllerTf two_dof_form(const core::StateSpace& c) {
  if (c.inputs() != 2 || c.outputs() != 1)
    throw std::invalid_argument("two_dof_form: expected a compensator with inputs [reference, y] and one output");
  const core::TransferFunction reference = core::to_transfer_function(c, 0, 0);
  const core::TransferFunction measurement = core::to_transfer_function(c, 0, 1);
  // Both are over det(sI − Ac); the reference's copy is replaced by the feedback's so the loop
  // algebra sees one denominator (they differ only by rounding).
  const core::Polynomial& den = measurement.den();
  return {core::TransferFunction(-1.0 * measurement.num(), den), core::TransferFunction(reference.num(), den)};
}

TwoMeasurementController two_measurement_form(const core::StateSpace& c) {
  if (c.inputs() != 3 || c.outputs() != 1)
    throw std::invalid_argument("two_measurement_form: expected a compensator with inputs [reference, wm, wl] and one output");
  const core::TransferFunction reference = core::to_transfer_function(c, 0, 0);
  const core::TransferFunction motor = core::to_transfer_function(c, 0, 1);
  const core::TransferFunction load = core::to_transfer_function(c, 0, 2);
  // All over det(sI − Ac); one copy of it for the loop algebra (as two_dof_form).
  const core::Polynomial& den = motor.den();
  return {{core::TransferFunction(-1.0 * motor.num(), den), core::TransferFunction(reference.num(), den)},
          core::TransferFunction(-1.0 * load.num(), den)};
}

ControllerTf velocity_form(const ControllerTf& position) {
  const core::Polynomial s{1.0, 0.0};
  const core::Polynomial den = position.feedback.den() * s;
  return {core::TransferFunction(position.feedback.num(), den), core::TransferFunction(position.reference.num() * s, den)};
}

double prefilter_time_constant(const VelocityLoop& loop, std::span<const double> grid, double peak_limit) {
  if (!loop.has_load()) throw std::invalid_argument("prefilter_time_constant: the loop has no load side");
  return prefilter_time_constant([&](double w) { return loop.load_tracking(w) / Complex(0.0, w); }, grid, peak_limit);
}

double prefilter_time_constant(const std::function<Complex(double)>& tracking, std::span<const double> grid,
                               double peak_limit, double rel_tol) {
  if (!(peak_limit > 0.0)) throw std::invalid_argument("prefilter_time_constant: the peak limit must be > 0");
  const auto peak = [&](double tau) {
    const auto f = [&](double w) { return tracking(w) / (tau * Complex(0.0, w) + 1.0); };
    return core::peak_on_grid(f, grid, rel_tol).value;
  };
  if (peak(0.0) <= peak_limit) return 0.0;
  double lo = 0.0, hi = 1.0;
  while (peak(hi) > peak_limit) {
    lo = hi;
    hi *= 2.0;
    if (hi > 1e9) throw std::invalid_argument("prefilter_time_constant: no prefilter meets the limit (static gain above it?)");
  }
  while (hi - lo > rel_tol * hi) {
    const double mid = 0.5 * (lo + hi);
    (peak(mid) > peak_limit ? lo : hi) = mid;
  }
  return hi;
}

core::StateSpace with_prefilter(const core::StateSpace& c, double tau) {
  if (tau == 0.0) return c;
  // F: x' = (r − x)/τ, y = x, feeding the compensator's reference input; the measurement passes.
  core::StateSpace f;
  f.A = Matrix::Constant(1, 1, -1.0 / tau);
  f.B = Matrix::Zero(1, 2);
  f.B(0, 0) = 1.0 / tau;
  f.C = Matrix::Zero(2, 1);
  f.C(0, 0) = 1.0;
  f.D = Matrix::Zero(2, 2);
  f.D(1, 1) = 1.0;
  return core::series(f, c);
}

}  // namespace servotwin::tuning
