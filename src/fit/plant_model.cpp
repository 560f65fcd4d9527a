#include "servotwin/fit/plant_model.hpp"

#include "servotwin/core/error.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;

Complex quadratic(const ModalPair& p, Complex s) {
  return s * s + 2.0 * p.zeta * p.omega_rad_s * s + p.omega_rad_s * p.omega_rad_s;
}

/// The load side's damping zero 2ζω s + ω² of a resonance (plant_model.hpp).
Complex damping_zero(const ModalPair& p, Complex s) { return 2.0 * p.zeta * p.omega_rad_s * s + p.omega_rad_s * p.omega_rad_s; }

core::Polynomial quadratic_polynomial(const ModalPair& p) {
  return core::Polynomial{1.0, 2.0 * p.zeta * p.omega_rad_s, p.omega_rad_s * p.omega_rad_s};
}

}  // namespace

std::string to_string(OutputKind output) { return output == OutputKind::kVelocity ? "velocity" : "position"; }
std::string to_string(RigidKind rigid) { return rigid == RigidKind::kRealPole ? "pole" : "integrator"; }
std::string to_string(SensorSide sensor) { return sensor == SensorSide::kMotor ? "motor" : "load"; }

void require_motor_side(const PlantModel& model, const std::string& what, const std::string& field) {
  if (model.sensor == SensorSide::kLoad && !model.modes.empty())
    throw core::InputError(core::at_field(field), what + " needs a motor-side model (each mode with its antiresonance); "
                                                  "this one was fitted from a load-side response (resonances alone): "
                                                  "measure with the motor encoder and fit that");
}

std::complex<double> PlantModel::response(double omega_rad_s) const noexcept {
  const Complex s(0.0, omega_rad_s);
  // Product of factor ratios rather than num/den polynomials: no overflow for many modes at
  // high frequency, and each factor is evaluated where it is well conditioned.
  Complex p = gain / (rigid == RigidKind::kRealPole ? s + rigid_pole_rad_s : s);
  for (const Mode& m : modes)
    p *= (sensor == SensorSide::kMotor ? quadratic(m.antiresonance, s) : damping_zero(m.resonance, s)) / quadratic(m.resonance, s);
  if (lag_pole_rad_s) p /= s + *lag_pole_rad_s;
  if (delay_s) p *= std::polar(1.0, -omega_rad_s * *delay_s);
  if (output == OutputKind::kPosition) p /= s;
  return p;
}

core::TransferFunction PlantModel::transfer_function() const {
  core::Polynomial num{gain};
  core::Polynomial den = rigid == RigidKind::kRealPole ? core::Polynomial{1.0, rigid_pole_rad_s} : core::Polynomial{1.0, 0.0};
  for (const Mode& m : modes) {
    num = num * (sensor == SensorSide::kMotor
                     ? quadratic_polynomial(m.antiresonance)
                     : core::Polynomial{2.0 * m.resonance.zeta * m.resonance.omega_rad_s,
                                        m.resonance.omega_rad_s * m.resonance.omega_rad_s});
    den = den * quadratic_polynomial(m.resonance);
  }
  if (lag_pole_rad_s) den = den * core::Polynomial{1.0, *lag_pole_rad_s};
  if (output == OutputKind::kPosition) den = den * core::Polynomial{1.0, 0.0};
  return core::TransferFunction(num, den);
}

std::size_t parameter_count(std::size_t modes, RigidKind rigid, bool lag, bool delay, SensorSide sensor) noexcept {
  return 1 + (rigid == RigidKind::kRealPole ? 1 : 0) + (sensor == SensorSide::kMotor ? 4 : 2) * modes + (lag ? 1 : 0) +
         (delay ? 1 : 0);
}

std::size_t PlantModel::parameter_count() const noexcept {
  return fit::parameter_count(modes.size(), rigid, lag_pole_rad_s.has_value(), delay_s.has_value(), sensor);
}

}  // namespace servotwin::fit
