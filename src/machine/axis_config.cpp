#include "field_errors.hpp"
#include "servotwin/machine/axis_config.hpp"

#include <cctype>
#include <cmath>
#include <complex>
#include <sstream>
#include <string>

#include <Eigen/Eigenvalues>

#include "servotwin/core/error.hpp"
#include "servotwin/machine/closed_loop.hpp"

namespace servotwin::machine {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

using detail::fail;
using detail::number;

// Small checkers: each names the field and the expectation.
void finite(double v, const std::string& field) {
  if (!std::isfinite(v)) fail(field, "expected a finite number, found " + number(v));
}
using detail::non_negative;
using detail::positive;
void non_positive(double v, const std::string& field) {
  if (!std::isfinite(v) || v > 0.0) fail(field, "expected a finite number <= 0, found " + number(v));
}

void validate_controller(const AxisConfig& axis, double ts, const std::string& p) {
  std::visit(
      [&](const auto& c) {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, PPiController>) {
          non_negative(c.kp, p + ".kp");
          non_negative(c.kv, p + ".kv");
          non_negative(c.ki, p + ".ki");
          finite(c.vel_ff, p + ".vel_ff");
          finite(c.acc_ff, p + ".acc_ff");
        } else if constexpr (std::is_same_v<T, PidController>) {
          non_negative(c.kp, p + ".kp");
          non_negative(c.ki, p + ".ki");
          non_negative(c.kd, p + ".kd");
          finite(c.vel_ff, p + ".vel_ff");
          finite(c.acc_ff, p + ".acc_ff");
        } else if constexpr (std::is_same_v<T, SlidingModeController>) {
          positive(c.lambda, p + ".lambda");
          non_negative(c.ks, p + ".ks");
          non_negative(c.rho, p + ".rho");
          if (c.model_inertia) positive(*c.model_inertia, p + ".model_inertia");
          if (c.model_damping) non_negative(*c.model_damping, p + ".model_damping");
          if (c.model_gain) positive(*c.model_gain, p + ".model_gain");
        } else {
          positive(c.wn_hz, p + ".wn_hz");
          positive(c.zeta, p + ".zeta");
          positive(c.kalman_process_noise, p + ".kalman_process_noise");
          positive(c.kalman_measurement_noise, p + ".kalman_measurement_noise");
          const double damped_hz = c.zeta < 1.0 ? c.wn_hz * std::sqrt(1.0 - c.zeta * c.zeta) : 0.0;
          if (!(damped_hz < 0.5 / ts))
            fail(p + ".wn_hz", "the damped frequency " + number(damped_hz) + " Hz must be below the Nyquist frequency " +
                                   number(0.5 / ts) + " Hz");
        }
      },
      axis.controller);
}

void validate_stability(const AxisConfig& axis, double ts, const std::string& prefix) {
  DiscreteClosedLoop loop;
  try {
    loop = discrete_closed_loop(axis, ts, true);
  } catch (const core::InputError& e) {
    fail(prefix + ".controller", e.reason());
  }
  const Eigen::MatrixXd a = loop.system.A.topLeftCorner(loop.loop_states, loop.loop_states);
  const Eigen::EigenSolver<Eigen::MatrixXd> solver(a, false);
  if (solver.info() != Eigen::Success) fail(prefix + ".controller", "could not compute the closed-loop poles");
  double worst = 0.0;
  std::complex<double> worst_pole;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    const std::complex<double> z = solver.eigenvalues()(i);
    if (std::abs(z) >= worst) {
      worst = std::abs(z);
      worst_pole = z;
    }
  }
  if (!(worst < 1.0))
    fail(prefix + ".controller", "the sampled closed loop is unstable at ts = " + number(ts) + " s: pole at z = " +
                                     number(worst_pole.real()) + (worst_pole.imag() < 0 ? " - " : " + ") + "j" +
                                     number(std::abs(worst_pole.imag())) + " (|z| = " + number(worst) +
                                     " >= 1); check the gains");
}

}  // namespace

const AxisConfig* MachineConfig::find(const std::string& axis_name) const noexcept {
  const std::string key = lower(axis_name);
  for (const auto& a : axes)
    if (lower(a.name) == key) return &a;
  return nullptr;
}

void validate(const AxisConfig& axis, double ts, const std::string& prefix) {
  const std::string& p = prefix;
  positive(ts, "ts");
  if (axis.name.empty()) fail(p + ".name", "expected a non-empty axis name");
  for (char c : axis.name)
    if (!(std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) || c == '_'))
      fail(p + ".name", "expected a lower-case name of letters, digits and '_' (it names CSV columns), found '" +
                            axis.name + "'");
  if (!std::islower(static_cast<unsigned char>(axis.name.front())))
    fail(p + ".name", "expected the name to start with a lower-case letter, found '" + axis.name + "'");
  finite(axis.home, p + ".home");
  positive(axis.plant.inertia, p + ".plant.inertia");
  non_negative(axis.plant.damping, p + ".plant.damping");
  positive(axis.plant.gain, p + ".plant.gain");

  const auto& nl = axis.nonlinear;
  const auto& f = nl.friction;
  const std::string pf = p + ".nonlinear.friction";
  non_negative(f.coulomb_pos, pf + ".coulomb_pos");
  non_positive(f.coulomb_neg, pf + ".coulomb_neg");
  if (f.static_pos) {
    finite(*f.static_pos, pf + ".static_pos");
    if (*f.static_pos < f.coulomb_pos)
      fail(pf + ".static_pos", "expected a stiction level >= coulomb_pos = " + number(f.coulomb_pos) + ", found " +
                                   number(*f.static_pos));
  }
  if (f.static_neg) {
    finite(*f.static_neg, pf + ".static_neg");
    if (*f.static_neg > f.coulomb_neg)
      fail(pf + ".static_neg", "expected a stiction level <= coulomb_neg = " + number(f.coulomb_neg) + ", found " +
                                   number(*f.static_neg));
  }
  non_negative(nl.backlash.width, p + ".nonlinear.backlash.width");
  if (!(nl.u_max > 0.0) || std::isnan(nl.u_max))
    fail(p + ".nonlinear.u_max", "expected a saturation level > 0 (infinity = none), found " + number(nl.u_max));
  if (nl.dac_bits != 0 && (nl.dac_bits < 2 || nl.dac_bits > 32))
    fail(p + ".nonlinear.dac_bits", "expected 0 (no DAC) or 2 ... 32 bits, found " + std::to_string(nl.dac_bits));
  positive(nl.dac_range, p + ".nonlinear.dac_range");
  non_negative(nl.encoder_resolution, p + ".nonlinear.encoder_resolution");
  non_negative(nl.encoder_noise_std, p + ".nonlinear.encoder_noise_std");
  if (nl.delay_samples < 0 || nl.delay_samples > 1)
    fail(p + ".nonlinear.delay_samples", "expected 0 or 1 samples of computation delay, found " +
                                             std::to_string(nl.delay_samples));

  validate_controller(axis, ts, p + ".controller");
  validate_stability(axis, ts, p);
}

void validate(const MachineConfig& machine) {
  positive(machine.ts, "ts");
  positive(machine.cnc.accel, "cnc.accel");
  if (machine.cnc.jerk) positive(*machine.cnc.jerk, "cnc.jerk");
  positive(machine.cnc.rapid_feed_mm_min, "cnc.rapid_feed_mm_min");
  if (!std::isfinite(machine.cnc.corner_angle_deg) || machine.cnc.corner_angle_deg < 0.0 ||
      machine.cnc.corner_angle_deg >= 180.0)
    fail("cnc.corner_angle_deg", "expected an angle in [0, 180) degrees, found " + number(machine.cnc.corner_angle_deg));
  if (machine.axes.empty()) fail("axes", "expected at least one axis");
  for (std::size_t i = 0; i < machine.axes.size(); ++i) {
    const std::string prefix = "axes[" + std::to_string(i) + "]";
    validate(machine.axes[i], machine.ts, prefix);
    for (std::size_t j = 0; j < i; ++j)
      if (lower(machine.axes[j].name) == lower(machine.axes[i].name))
        fail(prefix + ".name", "axis name '" + machine.axes[i].name + "' is used twice (also axes[" +
                                   std::to_string(j) + "])");
  }
}

}  // namespace servotwin::machine
