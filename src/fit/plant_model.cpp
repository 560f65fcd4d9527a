#include "servotwin/fit/plant_model.hpp"

namespace servotwin::fit {

namespace {

using Complex = std::complex<double>;

Complex quadratic(const ModalPair& p, Complex s) {
  return s * s + 2.0 * p.zeta * p.omega_rad_s * s + p.omega_rad_s * p.omega_rad_s;
}

core::Polynomial quadratic_polynomial(const ModalPair& p) {
  return core::Polynomial{1.0, 2.0 * p.zeta * p.omega_rad_s, p.omega_rad_s * p.omega_rad_s};
}

}  // namespace

std::string to_string(OutputKind output) { return output == OutputKind::kVelocity ? "velocity" : "position"; }
std::string to_string(RigidKind rigid) { return rigid == RigidKind::kRealPole ? "pole" : "integrator"; }

std::complex<double> PlantModel::response(double omega_rad_s) const noexcept {
  const Complex s(0.0, omega_rad_s);
  // Product of factor ratios rather than num/den polynomials: no overflow for many modes at
  // high frequency, and each factor is evaluated where it is well conditioned.
  Complex p = gain / (rigid == RigidKind::kRealPole ? s + rigid_pole_rad_s : s);
  for (const Mode& m : modes) p *= quadratic(m.antiresonance, s) / quadratic(m.resonance, s);
  if (lag_pole_rad_s) p /= s + *lag_pole_rad_s;
  if (delay_s) p *= std::polar(1.0, -omega_rad_s * *delay_s);
  if (output == OutputKind::kPosition) p /= s;
  return p;
}

core::TransferFunction PlantModel::transfer_function() const {
  core::Polynomial num{gain};
  core::Polynomial den = rigid == RigidKind::kRealPole ? core::Polynomial{1.0, rigid_pole_rad_s} : core::Polynomial{1.0, 0.0};
  for (const Mode& m : modes) {
    num = num * quadratic_polynomial(m.antiresonance);
    den = den * quadratic_polynomial(m.resonance);
  }
  if (lag_pole_rad_s) den = den * core::Polynomial{1.0, *lag_pole_rad_s};
  if (output == OutputKind::kPosition) den = den * core::Polynomial{1.0, 0.0};
  return core::TransferFunction(num, den);
}

std::size_t parameter_count(std::size_t modes, RigidKind rigid, bool lag, bool delay) noexcept {
  return 1 + (rigid == RigidKind::kRealPole ? 1 : 0) + 4 * modes + (lag ? 1 : 0) + (delay ? 1 : 0);
}

std::size_t PlantModel::parameter_count() const noexcept {
  return fit::parameter_count(modes.size(), rigid, lag_pole_rad_s.has_value(), delay_s.has_value());
}

}  // namespace servotwin::fit
