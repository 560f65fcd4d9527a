#include "servotwin/machine/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "servotwin/core/error.hpp"
#include "servotwin/machine/pole_placement.hpp"
#include "servotwin/machine/rigid_axis.hpp"

namespace servotwin::machine {

namespace {

using core::Polynomial;
using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::RowVectorXd;
using Eigen::VectorXd;
using Complex = std::complex<double>;

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

struct SmcModel {
  double j, b, k;
};
SmcModel smc_model(const SlidingModeController& c, const RigidPlant& plant) {
  return {c.model_inertia.value_or(plant.inertia), c.model_damping.value_or(plant.damping),
          c.model_gain.value_or(plant.gain)};
}

// ---- controller difference equations as a linear block ------------------------------------
//
// Window c = [x_r(k-1), x_r(k), ..., x_r(k+preview)], reading y = y(k), controller state z:
//   u(k) = cc z + dw c + dy y,   z(k+1) = ac z + bw c + by y.
struct ControllerBlock {
  int preview = 1;
  MatrixXd ac, bw;
  VectorXd by;
  RowVectorXd cc, dw;
  double dy = 0.0;
};

// A linear form in [x_r(k-1), x_r(k), x_r(k+1), y(k), y(k-1), I(k-1)]: the PID-family
// controllers (state z = [I(k-1), y(k-1)], I an integrator or the adapted disturbance).
struct Form {
  Eigen::Matrix<double, 1, 6> c = Eigen::Matrix<double, 1, 6>::Zero();
  static Form unit(int i) {
    Form f;
    f.c(i) = 1.0;
    return f;
  }
  friend Form operator+(Form a, const Form& b) {
    a.c += b.c;
    return a;
  }
  friend Form operator-(Form a, const Form& b) {
    a.c -= b.c;
    return a;
  }
  friend Form operator*(double k, Form a) {
    a.c *= k;
    return a;
  }
};
enum : int { kXPrev = 0, kX = 1, kXNext = 2, kY = 3, kYPrev = 4, kIPrev = 5 };

// u = u_form, I(k) = I(k-1) + increment (increment must not contain I(k-1)).
ControllerBlock integral_block(const Form& u, const Form& increment) {
  ControllerBlock b;
  b.preview = 1;
  b.cc.resize(2);
  b.cc << u.c(kIPrev), u.c(kYPrev);
  b.dw = u.c.head<3>();
  b.dy = u.c(kY);
  b.ac = MatrixXd::Zero(2, 2);
  b.ac(0, 0) = 1.0;
  b.ac(0, 1) = increment.c(kYPrev);
  b.bw = MatrixXd::Zero(2, 3);
  b.bw.row(0) = increment.c.head<3>();
  b.by = VectorXd::Zero(2);
  b.by(0) = increment.c(kY);
  b.by(1) = 1.0;  // y(k-1) <- y(k)
  return b;
}

struct Derivatives {
  Form ref_velocity, ref_acceleration, meas_velocity, error;
};
Derivatives derivatives(double ts) {
  const Form xp = Form::unit(kXPrev), x = Form::unit(kX), xn = Form::unit(kXNext);
  const Form y = Form::unit(kY), yp = Form::unit(kYPrev);
  return {(0.5 / ts) * (xn - xp), (1.0 / (ts * ts)) * (xn - 2.0 * x + xp), (1.0 / ts) * (y - yp), x - y};
}

ControllerBlock block_of(const PidController& c, double ts) {
  const Derivatives d = derivatives(ts);
  const Form increment = ts * d.error;
  const Form integral = Form::unit(kIPrev) + increment;
  const Form u = c.kp * d.error + c.ki * integral + c.kd * (d.ref_velocity - d.meas_velocity) +
                 c.vel_ff * d.ref_velocity + c.acc_ff * d.ref_acceleration;
  return integral_block(u, increment);
}

ControllerBlock block_of(const PPiController& c, double ts) {
  const Derivatives d = derivatives(ts);
  const Form velocity_error = c.kp * d.error + c.vel_ff * d.ref_velocity - d.meas_velocity;
  const Form increment = ts * velocity_error;
  const Form u = c.kv * velocity_error + c.ki * (Form::unit(kIPrev) + increment) + c.acc_ff * d.ref_acceleration;
  return integral_block(u, increment);
}

ControllerBlock block_of(const SlidingModeController& c, const RigidPlant& plant, double ts) {
  const Derivatives d = derivatives(ts);
  const SmcModel m = smc_model(c, plant);
  const Form error_rate = d.ref_velocity - d.meas_velocity;
  const Form surface = error_rate + c.lambda * d.error;
  const Form increment = (ts * c.rho) * surface;
  const Form u = (m.j / m.k) * (d.ref_acceleration + c.lambda * error_rate) +
                 (m.b / m.k) * (d.ref_velocity + c.lambda * d.error) + c.ks * surface +
                 (Form::unit(kIPrev) + increment);
  return integral_block(u, increment);
}

ControllerBlock block_of(const PolePlacementDesign& d) {
  ControllerBlock b;
  b.preview = d.preview;
  const Index na = d.phi_a.rows();
  const Index window = d.preview + 2;
  RowVectorXd kc(na);  // u = N x_r* - kc X_hat(k|k)
  kc.head(na - 1) = d.feedback;
  kc(na - 1) = -d.disturbance_gain;
  const MatrixXd i_mc = MatrixXd::Identity(na, na) - d.kalman_gain * RowVectorXd::Unit(na, 0);
  b.cc = -kc * i_mc;
  b.dy = -kc.dot(d.kalman_gain);
  b.dw = RowVectorXd::Zero(window);
  if (d.zpetc) {
    for (std::size_t j = 0; j < d.zpetc_taps.size(); ++j)
      b.dw(d.preview + 1 - static_cast<Index>(j)) = d.reference_gain * d.zpetc_taps[j];
  } else {
    b.dw(1) = d.reference_gain;
  }
  b.ac = d.phi_a * i_mc + d.gamma_a * b.cc;
  b.by = d.phi_a * d.kalman_gain + d.gamma_a * b.dy;
  b.bw = d.gamma_a * b.dw;
  return b;
}

ControllerBlock controller_block(const AxisConfig& axis, double ts) {
  return std::visit(Overloaded{[&](const PidController& c) { return block_of(c, ts); },
                               [&](const PPiController& c) { return block_of(c, ts); },
                               [&](const SlidingModeController& c) { return block_of(c, axis.plant, ts); },
                               [&](const PolePlacementController& c) {
                                 return block_of(design_pole_placement(axis.plant, c, ts,
                                                                       axis.nonlinear.delay_samples));
                               }},
                    axis.controller);
}

struct PlantSampled {
  double e, p1, p2, kj;
};
PlantSampled sampled_plant(const RigidPlant& plant, double ts) {
  const double a = plant.damping / plant.inertia;
  return {std::exp(-a * ts), RigidAxisDynamics::phi1(a, ts), RigidAxisDynamics::phi2(a, ts),
          plant.gain / plant.inertia};
}

// ---- frequency responses of the discrete loop ----------------------------------------------

struct LoopResponse {
  Complex tracking, disturbance;
};
LoopResponse loop_response(const DiscreteClosedLoop& loop, double omega) {
  const auto& sys = loop.system;
  const double ts = sys.ts;
  const Complex z = std::exp(Complex(0.0, omega * ts));
  Eigen::MatrixXcd m = -sys.A.cast<Complex>();
  m.diagonal().array() += z;
  const Eigen::MatrixXcd x = m.partialPivLu().solve(sys.B.cast<Complex>());
  const Eigen::RowVectorXcd c = sys.C.row(0).cast<Complex>();
  const Complex tracking = (c * x.col(0))(0) * std::pow(z, loop.preview);
  const Complex disturbance = (c * x.col(1))(0);
  return {tracking, disturbance};
}

Complex eval_tracking(const ClosedLoopCoefficients& c, Complex s) {
  const Complex den = ((s + c.a1) * s + c.a2) * s + c.a3;
  return (((c.b0 * s + c.b1) * s + c.b2) * s + c.a3) / den;
}
Complex eval_disturbance(const ClosedLoopCoefficients& c, Complex s) {
  const Complex den = ((s + c.a1) * s + c.a2) * s + c.a3;
  return -s / den;
}

}  // namespace

// ---- continuous mapping -----------------------------------------------------------------------

ClosedLoopCoefficients closed_loop_coefficients(const RigidPlant& plant, const TwoDofPid& law,
                                                const Friction& friction) {
  if (!(plant.inertia > 0.0) || !(plant.gain > 0.0))
    throw core::InputError(core::SourceLocation{"", 0, 0, "plant"},
                           "inertia and gain must be > 0 to form the closed loop");
  if (std::abs(law.r0 - law.c0) > 1e-12 * std::max(std::abs(law.r0), std::abs(law.c0)))
    throw core::InputError(core::SourceLocation{"", 0, 0, "controller"},
                           "Eq. 3.3 needs the integral to act on the tracking error (r0 == c0), found r0 = " +
                               std::to_string(law.r0) + ", c0 = " + std::to_string(law.c0));
  const double kj = plant.gain / plant.inertia;
  ClosedLoopCoefficients c;
  c.a1 = (plant.damping + plant.gain * law.c2) / plant.inertia;
  c.a2 = kj * law.c1;
  c.a3 = kj * law.c0;
  c.b0 = kj * law.r3;
  c.b1 = kj * law.r2;
  c.b2 = kj * law.r1;
  c.d0 = friction.coulomb_pos / plant.inertia;
  c.d1 = friction.coulomb_neg / plant.inertia;
  return c;
}

TwoDofPid two_dof_law(const Controller& controller, const RigidPlant& plant) {
  return std::visit(
      Overloaded{[](const PPiController& c) {
                   TwoDofPid l;
                   l.c2 = c.kv;
                   l.c1 = c.kv * c.kp + c.ki;
                   l.c0 = c.ki * c.kp;
                   l.r3 = c.acc_ff;
                   l.r2 = c.kv * c.vel_ff;
                   l.r1 = c.kv * c.kp + c.ki * c.vel_ff;
                   l.r0 = l.c0;
                   return l;
                 },
                 [](const PidController& c) {
                   TwoDofPid l;
                   l.c2 = c.kd;
                   l.c1 = c.kp;
                   l.c0 = c.ki;
                   l.r3 = c.acc_ff;
                   l.r2 = c.kd + c.vel_ff;
                   l.r1 = c.kp;
                   l.r0 = c.ki;
                   return l;
                 },
                 [&](const SlidingModeController& c) {
                   const SmcModel m = smc_model(c, plant);
                   TwoDofPid l;
                   l.c2 = m.j * c.lambda / m.k + c.ks;
                   l.c1 = m.b * c.lambda / m.k + c.ks * c.lambda + c.rho;
                   l.c0 = c.rho * c.lambda;
                   l.r3 = m.j / m.k;
                   l.r2 = m.b / m.k + l.c2;
                   l.r1 = l.c1;
                   l.r0 = l.c0;
                   return l;
                 },
                 [](const PolePlacementController&) -> TwoDofPid {
                   throw std::invalid_argument(
                       "two_dof_law: a discrete pole-placement controller has no continuous two-DOF PID form");
                 }},
      controller);
}

TwoDofPid thesis_ppi_law(double Kp, double Kd, double Ki, double Kv, double Ka) {
  // u = (Kd + Ki/s)(Kp (1 + Kv s + Ka s^2) x_r - (Kp + s) x)
  TwoDofPid l;
  l.c2 = Kd;
  l.c1 = Kd * Kp + Ki;
  l.c0 = Ki * Kp;
  l.r3 = Kd * Kp * Ka;
  l.r2 = Kp * (Kd * Kv + Ki * Ka);
  l.r1 = Kp * (Kd + Ki * Kv);
  l.r0 = Kp * Ki;
  return l;
}

TwoDofPid thesis_pid_law(double Kp, double Ki, double Kd, double Kv, double Ka) {
  TwoDofPid l;
  l.c2 = Kd;
  l.c1 = Kp;
  l.c0 = Ki;
  l.r3 = Ka;
  l.r2 = Kd + Kv;
  l.r1 = Kp;
  l.r0 = Ki;
  return l;
}

core::TransferFunction tracking_tf(const ClosedLoopCoefficients& c) {
  return {Polynomial{c.b0, c.b1, c.b2, c.a3}, Polynomial{1.0, c.a1, c.a2, c.a3}};
}

core::TransferFunction disturbance_tf(const ClosedLoopCoefficients& c) {
  return {Polynomial{-1.0, 0.0}, Polynomial{1.0, c.a1, c.a2, c.a3}};
}

// ---- sampled loop ----------------------------------------------------------------------------

int command_preview(const AxisConfig& axis) {
  if (const auto* pp = std::get_if<PolePlacementController>(&axis.controller))
    return pp->zpetc ? 2 + axis.nonlinear.delay_samples : 0;
  return 1;
}

DiscreteClosedLoop discrete_closed_loop(const AxisConfig& axis, double ts, bool include_delay) {
  const ControllerBlock ctl = controller_block(axis, ts);
  const PlantSampled p = sampled_plant(axis.plant, ts);
  const Index nd = include_delay ? axis.nonlinear.delay_samples : 0;
  const Index nz = ctl.ac.rows();
  const Index nh = ctl.preview + 1;  // x_r(k-1) ... x_r(k+preview-1)
  const Index i_buf = 2, i_z = 2 + nd, i_h = 2 + nd + nz;
  const Index n = i_h + nh;

  // u(k) as a row over the state, plus its coefficient on the newest command input.
  RowVectorXd u_row = ctl.dy * RowVectorXd::Unit(n, 0);
  u_row.segment(i_z, nz) = ctl.cc;
  u_row.segment(i_h, nh) = ctl.dw.head(nh);
  const double u_in = ctl.dw(nh);
  // Applied control: the oldest entry of the delay line, or u(k) itself.
  RowVectorXd ua_row = RowVectorXd::Zero(n);
  double ua_in = 0.0;
  if (nd > 0) {
    ua_row(i_buf + nd - 1) = 1.0;
  } else {
    ua_row = u_row;
    ua_in = u_in;
  }

  DiscreteClosedLoop out;
  out.preview = ctl.preview;
  out.loop_states = i_h;
  auto& sys = out.system;
  sys.ts = ts;
  sys.A = MatrixXd::Zero(n, n);
  sys.B = MatrixXd::Zero(n, 2);
  // Plant: exact ZOH of J x'' + B x' = K u - J d.
  const Eigen::Vector2d gu(p.kj * p.p2, p.kj * p.p1), gd(p.p2, p.p1);
  sys.A(0, 0) = 1.0;
  sys.A(0, 1) = p.p1;
  sys.A(1, 1) = p.e;
  sys.A.topRows(2) += gu * ua_row;
  sys.B.block(0, 0, 2, 1) = gu * ua_in;
  sys.B.block(0, 1, 2, 1) = -gd;
  // Delay line.
  if (nd > 0) {
    sys.A.row(i_buf) = u_row;
    sys.B(i_buf, 0) = u_in;
    for (Index i = 1; i < nd; ++i) sys.A(i_buf + i, i_buf + i - 1) = 1.0;
  }
  // Controller.
  sys.A.block(i_z, i_z, nz, nz) = ctl.ac;
  sys.A.block(i_z, 0, nz, 1) = ctl.by;
  sys.A.block(i_z, i_h, nz, nh) = ctl.bw.leftCols(nh);
  sys.B.block(i_z, 0, nz, 1) = ctl.bw.col(nh);
  // Command shift register.
  for (Index i = 0; i + 1 < nh; ++i) sys.A(i_h + i, i_h + i + 1) = 1.0;
  sys.B(i_h + nh - 1, 0) = 1.0;
  // Outputs.
  sys.C = MatrixXd::Zero(2, n);
  sys.C(0, 0) = 1.0;
  sys.C.row(1) = ua_row;
  sys.D = MatrixXd::Zero(2, 2);
  sys.D(1, 0) = ua_in;
  return out;
}

std::complex<double> DiscreteTransferFunction::frequency_response(double omega_rad_s) const noexcept {
  const Complex z = std::exp(Complex(0.0, omega_rad_s * ts));
  return num(z) / den(z);
}

DiscreteTransferFunction discrete_tracking_tf(const AxisConfig& axis, double ts) {
  const PlantSampled p = sampled_plant(axis.plant, ts);
  const Polynomial n{p.kj * p.p2, p.kj * (p.p1 * p.p1 - p.e * p.p2)};
  const Polynomial a = Polynomial{1.0, -1.0} * Polynomial{1.0, -p.e};
  Polynomial z_delay{1.0};
  for (int i = 0; i < axis.nonlinear.delay_samples; ++i) z_delay = z_delay * Polynomial{1.0, 0.0};

  DiscreteTransferFunction out;
  out.ts = ts;
  if (const auto* pp = std::get_if<PolePlacementController>(&axis.controller)) {
    const PolePlacementDesign d = design_pole_placement(axis.plant, *pp, ts, axis.nonlinear.delay_samples);
    const Polynomial a_cl(d.closed_loop_den);
    if (d.zpetc) {
      out.num = d.reference_gain * (n * Polynomial(d.zpetc_taps));
      out.den = a_cl * Polynomial{1.0, 0.0};
    } else {
      out.num = d.reference_gain * n;
      out.den = a_cl;
    }
    return out;
  }

  // u = (R x_r - S y) / Q with Q = ts^2 z (z - 1).
  const Polynomial z{1.0, 0.0}, zm1{1.0, -1.0}, z2m1{1.0, 0.0, -1.0};
  const Polynomial q = (ts * ts) * (z * zm1);
  const Polynomial zm1_sq = zm1 * zm1, zm1_cu = zm1_sq * zm1;
  Polynomial r, s;
  std::visit(Overloaded{[&](const PidController& c) {
                          const Polynomial common = (c.kp * ts * ts) * (z * zm1) + (c.ki * ts * ts * ts) * (z * z);
                          s = common + (c.kd * ts) * zm1_sq;
                          r = common + (0.5 * (c.kd + c.vel_ff) * ts) * (z2m1 * zm1) + c.acc_ff * zm1_cu;
                        },
                        [&](const PPiController& c) {
                          const Polynomial pi = c.kv * zm1 + (c.ki * ts) * z;
                          s = pi * ((c.kp * ts * ts) * z + ts * zm1);
                          r = pi * ((c.kp * ts * ts) * z + (0.5 * c.vel_ff * ts) * z2m1) + c.acc_ff * zm1_cu;
                        },
                        [&](const SlidingModeController& c) {
                          const SmcModel m = smc_model(c, axis.plant);
                          const double jm = m.j / m.k, bm = m.b / m.k, lam = c.lambda;
                          const Polynomial g = (c.ks * ts) * zm1 + (c.rho * ts * ts) * z;
                          s = (jm * lam * ts) * zm1_sq + (bm * lam * ts * ts) * (z * zm1) + g * (zm1 + (lam * ts) * z);
                          r = jm * (zm1_cu + (0.5 * lam * ts) * (z2m1 * zm1)) +
                              bm * ((0.5 * ts) * (z2m1 * zm1) + (lam * ts * ts) * (z * zm1)) +
                              0.5 * (g * (z2m1 + (2.0 * lam * ts) * z));
                        },
                        [](const PolePlacementController&) {}},
             axis.controller);
  out.num = n * r;
  out.den = a * z_delay * q + n * s;
  return out;
}

EquivalentFit fit_equivalent_coefficients(const AxisConfig& axis, double ts, double f_max_hz, double f_min_hz,
                                          int points) {
  const double nyquist_hz = 0.5 / ts;
  if (f_max_hz <= 0.0) f_max_hz = nyquist_hz / 4.0;
  if (!(f_min_hz > 0.0) || !(f_max_hz > f_min_hz) || f_max_hz >= nyquist_hz || points < 8)
    throw core::InputError(core::SourceLocation{"", 0, 0, "fit"},
                           "expected 0 < f_min < f_max < Nyquist and at least 8 frequencies");
  const DiscreteClosedLoop loop = discrete_closed_loop(axis, ts, true);
  const std::vector<double> freqs =
      core::log_space(f_min_hz, f_max_hz, static_cast<std::size_t>(points));
  const auto np = static_cast<Index>(points);
  std::vector<Complex> s(freqs.size()), t(freqs.size()), g(freqs.size());
  for (std::size_t i = 0; i < freqs.size(); ++i) {
    const double w = 2.0 * std::numbers::pi * freqs[i];
    s[i] = Complex(0.0, w);
    const LoopResponse r = loop_response(loop, w);
    t[i] = r.tracking;
    g[i] = r.disturbance;
  }

  // Unknowns theta = [a1 a2 a3 b0 b1 b2]; per frequency two complex equations:
  //   a1 s^2 T + a2 s T + a3 (T - 1) - b0 s^3 - b1 s^2 - b2 s = -s^3 T
  //   a1 s^2 G + a2 s G + a3 G = -s - s^3 G
  const double w_ref = 2.0 * std::numbers::pi * std::sqrt(f_min_hz * f_max_hz);
  std::vector<Complex> d_prev(freqs.size());
  for (std::size_t i = 0; i < freqs.size(); ++i) d_prev[i] = std::pow(s[i] + w_ref, 3);
  ClosedLoopCoefficients c;
  Eigen::Matrix<double, 6, 1> theta = Eigen::Matrix<double, 6, 1>::Zero();
  int iterations = 0;
  for (int it = 0; it < 100; ++it) {
    MatrixXd a(4 * np, 6);
    VectorXd rhs(4 * np);
    for (Index i = 0; i < np; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Complex si = s[k], ti = t[k], gi = g[k];
      const double wt = 1.0 / std::abs(d_prev[k]);
      const double wd = wt / std::abs(gi);
      const Complex row_t[6] = {si * si * ti, si * ti, ti - 1.0, -si * si * si, -si * si, -si};
      const Complex rhs_t = -si * si * si * ti;
      const Complex row_d[6] = {si * si * gi, si * gi, gi, 0.0, 0.0, 0.0};
      const Complex rhs_d = -si - si * si * si * gi;
      for (int j = 0; j < 6; ++j) {
        a(4 * i, j) = wt * row_t[j].real();
        a(4 * i + 1, j) = wt * row_t[j].imag();
        a(4 * i + 2, j) = wd * row_d[j].real();
        a(4 * i + 3, j) = wd * row_d[j].imag();
      }
      rhs(4 * i) = wt * rhs_t.real();
      rhs(4 * i + 1) = wt * rhs_t.imag();
      rhs(4 * i + 2) = wd * rhs_d.real();
      rhs(4 * i + 3) = wd * rhs_d.imag();
    }
    const Eigen::Matrix<double, 1, 6> norms = a.colwise().norm();
    for (int j = 0; j < 6; ++j) a.col(j) /= norms(j);
    Eigen::Matrix<double, 6, 1> next = a.colPivHouseholderQr().solve(rhs);
    next.array() /= norms.transpose().array();
    const double change = (next - theta).cwiseAbs().cwiseQuotient(next.cwiseAbs().cwiseMax(1e-300)).maxCoeff();
    theta = next;
    iterations = it + 1;
    c.a1 = theta(0);
    c.a2 = theta(1);
    c.a3 = theta(2);
    c.b0 = theta(3);
    c.b1 = theta(4);
    c.b2 = theta(5);
    for (std::size_t i = 0; i < freqs.size(); ++i) d_prev[i] = ((s[i] + c.a1) * s[i] + c.a2) * s[i] + c.a3;
    if (change < 1e-12) break;
  }
  EquivalentFit fit;
  fit.coefficients = c;
  fit.coefficients.d0 = axis.nonlinear.friction.coulomb_pos / axis.plant.inertia;
  fit.coefficients.d1 = axis.nonlinear.friction.coulomb_neg / axis.plant.inertia;
  fit.f_min_hz = f_min_hz;
  fit.f_max_hz = f_max_hz;
  fit.points = points;
  fit.iterations = iterations;
  for (std::size_t i = 0; i < freqs.size(); ++i) {
    fit.max_tracking_error = std::max(fit.max_tracking_error, std::abs(eval_tracking(c, s[i]) - t[i]));
    fit.max_disturbance_error =
        std::max(fit.max_disturbance_error, std::abs(eval_disturbance(c, s[i]) - g[i]) / std::abs(g[i]));
  }
  return fit;
}

EquivalentClosedLoop equivalent_closed_loop(const AxisConfig& axis, double ts) {
  EquivalentClosedLoop out;
  out.preview = command_preview(axis);
  if (std::holds_alternative<PolePlacementController>(axis.controller)) {
    const EquivalentFit fit = fit_equivalent_coefficients(axis, ts);
    out.coefficients = fit.coefficients;
    out.exact = false;
    out.method = "least-squares fit (Sanathanan-Koerner) of Eq. 3.3's tracking and disturbance responses to the "
                 "exact sampled closed loop, " +
                 std::to_string(fit.points) + " log-spaced frequencies " + std::to_string(fit.f_min_hz) + "-" +
                 std::to_string(fit.f_max_hz) + " Hz (a quarter of Nyquist); max tracking error " +
                 std::to_string(fit.max_tracking_error) + ", max relative disturbance error " +
                 std::to_string(fit.max_disturbance_error);
    out.fit = fit;
  } else {
    out.coefficients = closed_loop_coefficients(axis.plant, two_dof_law(axis.controller, axis.plant),
                                                axis.nonlinear.friction);
    out.exact = true;
    out.method = "exact: continuous-time controller law mapped to Eq. 3.3";
  }
  const core::TransferFunction g = tracking_tf(out.coefficients);
  for (const auto& r : g.poles()) out.poles.push_back(core::modal_info(r));
  for (const auto& r : g.zeros()) out.zeros.push_back(core::modal_info(r));
  const DiscreteTransferFunction dt = discrete_tracking_tf(axis, ts);
  out.discrete_poles = dt.den.roots();
  out.discrete_zeros = dt.num.roots();
  return out;
}

}  // namespace servotwin::machine
