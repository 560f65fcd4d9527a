#include "servotwin/tuning/normalized_plant.hpp"

#include <algorithm>
#include <cmath>

#include "checks.hpp"
#include "servotwin/core/error.hpp"

namespace servotwin::tuning {

namespace {

using Complex = std::complex<double>;
using core::InputError;
using core::Polynomial;
using detail::show;

constexpr double kMinResonanceRatio = 1.05;

Complex first_order_lag(double time_constant, double omega) { return 1.0 / Complex(1.0, omega * time_constant); }

Complex quadratic(const fit::ModalPair& p, Complex s) {
  return s * s + 2.0 * p.zeta * p.omega_rad_s * s + p.omega_rad_s * p.omega_rad_s;
}

Polynomial quadratic_polynomial(const fit::ModalPair& p) {
  return Polynomial{1.0, 2.0 * p.zeta * p.omega_rad_s, p.omega_rad_s * p.omega_rad_s};
}

/// The root of s² + 2ζωs + ω² with the larger real part (the offending one for ζ < 0).
Complex rightmost_root(const fit::ModalPair& p) {
  const double w = p.omega_rad_s, z = p.zeta;
  if (std::abs(z) < 1.0) return {-z * w, w * std::sqrt(1.0 - z * z)};
  return {-z * w + w * std::sqrt(z * z - 1.0), 0.0};
}

std::string mode_field(std::size_t index, const char* part) {
  return "modes[" + std::to_string(index) + "]." + part;
}

void check_pair(const fit::ModalPair& p, std::size_t index, bool zeros) {
  const char* part = zeros ? "antiresonance" : "resonance";
  detail::require_positive(p.omega_rad_s, mode_field(index, part) + ".omega_rad_s", "a frequency [rad/s]");
  detail::require_finite(p.zeta, mode_field(index, part) + ".zeta");
  if (p.zeta >= 0.0) return;
  const std::string where = "mode " + std::to_string(index + 1) + " " + part + (zeros ? " zero" : " pole") +
                            " pair at s = " + show(rightmost_root(p)) + " rad/s (zeta = " + show(p.zeta) + ")";
  if (zeros)
    throw InputError(core::at_field(mode_field(index, part) + ".zeta"),
                     "non-minimum-phase fit: " + where +
                         "; a motor-side (collocated) plant has minimum-phase zeros: refit or check the measurement");
  throw InputError(core::at_field(mode_field(index, part) + ".zeta"),
                   "unstable fit: " + where + "; refit with a stable model");
}

void check_rigid_and_gain(const fit::PlantModel& m) {
  if (m.output != fit::OutputKind::kVelocity && m.output != fit::OutputKind::kPosition)
    throw InputError(core::at_field("output"), "expected a velocity or position output");
  if (!std::isfinite(m.gain) || m.gain <= 0.0)
    throw InputError(core::at_field("gain"), "expected a gain K > 0, got " + show(m.gain) +
                                                 " (a negative gain means torque and measurement signs disagree: flip one)");
  if (m.rigid == fit::RigidKind::kIntegrator) return;
  if (m.rigid != fit::RigidKind::kRealPole) throw InputError(core::at_field("rigid"), "expected a pole or an integrator");
  detail::require_finite(m.rigid_pole_rad_s, "rigid_pole_rad_s");
  if (m.rigid_pole_rad_s < 0.0)
    throw InputError(core::at_field("rigid_pole_rad_s"),
                     "unstable fit: rigid-body pole at s = +" + show(-m.rigid_pole_rad_s) + " rad/s; refit with a stable model");
}

void check_modes(const fit::PlantModel& m) {
  fit::require_motor_side(m, "controller tuning (C7)", "sensor");
  if (m.modes.empty())
    throw InputError(core::at_field("modes"), "not a flexible plant: use a rigid-body tuning (the model has no mode)");
  for (std::size_t i = 0; i < m.modes.size(); ++i) {
    check_pair(m.modes[i].antiresonance, i, true);
    check_pair(m.modes[i].resonance, i, false);
  }
}

void check_lag_and_delay(const fit::PlantModel& m, const HfDynamics& hf) {
  if (m.lag_pole_rad_s) {
    detail::require_finite(*m.lag_pole_rad_s, "lag_pole_rad_s");
    if (*m.lag_pole_rad_s <= 0.0)
      throw InputError(core::at_field("lag_pole_rad_s"), "unstable fit: lag pole at s = " + show(-*m.lag_pole_rad_s) +
                                                             " rad/s; expected a pole p > 0 of 1/(s + p)");
    if (hf.lag_pole_rad_s)
      throw InputError(core::at_field("hf.lag_pole_rad_s"),
                       "the plant model already has a lag pole (" + show(*m.lag_pole_rad_s) + " rad/s): give it once");
  }
  if (m.delay_s) detail::require_non_negative(*m.delay_s, "delay_s", "a delay [s]");
  validate(hf, "hf");
}

std::vector<fit::Mode> sorted_modes(std::vector<fit::Mode> modes) {
  std::stable_sort(modes.begin(), modes.end(), [](const fit::Mode& x, const fit::Mode& y) {
    return x.resonance.omega_rad_s < y.resonance.omega_rad_s;
  });
  return modes;
}

void check_resonance_ratio(const fit::Mode& first) {
  const double r = first.resonance.omega_rad_s / first.antiresonance.omega_rad_s;
  if (r > kMinResonanceRatio) return;
  throw InputError(core::at_field("modes"),
                   "antiresonance above resonance: non-collocated or mis-fitted (first mode, i.e. lowest resonance: "
                   "antiresonance " +
                       show(first.antiresonance.omega_rad_s) + " rad/s, resonance " +
                       show(first.resonance.omega_rad_s) + " rad/s, r = " + show(r) +
                       "; a motor-side plant for this tuning needs r > 1.05)");
}

/// Everything known about the loop's HF dynamics in physical units: the user's, plus the model's
/// lag (as the unit-DC-gain p/(s + p)) and delay.
HfDynamics merged_hf(const fit::PlantModel& m, HfDynamics hf) {
  if (m.lag_pole_rad_s) hf.lag_pole_rad_s = m.lag_pole_rad_s;
  if (m.delay_s) hf.delay_s = hf.delay_s.value_or(0.0) + *m.delay_s;
  return hf;
}

fit::Mode normalized_mode(const fit::Mode& m, double omega_z) {
  fit::Mode n = m;
  n.antiresonance.omega_rad_s /= omega_z;
  n.resonance.omega_rad_s /= omega_z;
  return n;
}

/// DC gain ωz²/ωn² of one mode's ratio of quadratics.
double mode_dc_gain(const fit::Mode& m) {
  const double q = m.antiresonance.omega_rad_s / m.resonance.omega_rad_s;
  return q * q;
}

}  // namespace

// ---------------------------------------------------------------- HfDynamics

bool HfDynamics::empty() const noexcept {
  return !current_lag_s && !feedback_filter_s && !delay_s && !lag_pole_rad_s;
}

std::complex<double> HfDynamics::actuator_response(double omega) const noexcept {
  Complex h = 1.0;
  if (current_lag_s) h *= first_order_lag(*current_lag_s, omega);
  if (lag_pole_rad_s) h *= *lag_pole_rad_s / Complex(*lag_pole_rad_s, omega);
  if (delay_s) h *= std::polar(1.0, -omega * *delay_s);
  return h;
}

std::complex<double> HfDynamics::feedback_response(double omega) const noexcept {
  return feedback_filter_s ? first_order_lag(*feedback_filter_s, omega) : Complex(1.0);
}

std::complex<double> HfDynamics::response(double omega) const noexcept {
  return actuator_response(omega) * feedback_response(omega);
}

core::TransferFunction HfDynamics::actuator_rational() const {
  Polynomial num{1.0}, den{1.0};
  if (current_lag_s) den = den * Polynomial{*current_lag_s, 1.0};
  if (lag_pole_rad_s) {
    num = *lag_pole_rad_s * num;
    den = den * Polynomial{1.0, *lag_pole_rad_s};
  }
  return {num, den};
}

core::TransferFunction HfDynamics::feedback_rational() const {
  if (!feedback_filter_s) return {Polynomial{1.0}, Polynomial{1.0}};
  return {Polynomial{1.0}, Polynomial{*feedback_filter_s, 1.0}};
}

HfDynamics HfDynamics::time_scaled(double omega_z) const {
  HfDynamics h;
  if (current_lag_s) h.current_lag_s = *current_lag_s * omega_z;
  if (feedback_filter_s) h.feedback_filter_s = *feedback_filter_s * omega_z;
  if (delay_s) h.delay_s = *delay_s * omega_z;
  if (lag_pole_rad_s) h.lag_pole_rad_s = *lag_pole_rad_s / omega_z;
  return h;
}

void validate(const HfDynamics& hf, const std::string& prefix) {
  if (hf.current_lag_s) detail::require_positive(*hf.current_lag_s, prefix + ".current_lag_s", "a time constant [s]");
  if (hf.feedback_filter_s)
    detail::require_positive(*hf.feedback_filter_s, prefix + ".feedback_filter_s", "a time constant [s]");
  if (hf.delay_s) detail::require_non_negative(*hf.delay_s, prefix + ".delay_s", "a delay [s]");
  if (hf.lag_pole_rad_s) detail::require_positive(*hf.lag_pole_rad_s, prefix + ".lag_pole_rad_s", "a lag pole [rad/s]");
}

// ---------------------------------------------------------------- NormalizedPlant

core::TransferFunction mode_factor(const fit::Mode& mode) {
  return {(1.0 / mode_dc_gain(mode)) * quadratic_polynomial(mode.antiresonance), quadratic_polynomial(mode.resonance)};
}

core::TransferFunction NormalizedPlant::motor(bool with_higher_modes) const {
  Polynomial num{1.0, 2.0 * zeta_z, 1.0};
  Polynomial den = Polynomial{1.0, a} * Polynomial{1.0, 2.0 * zeta_p * r, r * r};
  if (with_higher_modes) {
    for (const fit::Mode& m : higher_modes) {
      const core::TransferFunction factor = mode_factor(m);
      num = num * factor.num();
      den = den * factor.den();
    }
  }
  return {num, den};
}

std::optional<core::TransferFunction> NormalizedPlant::load() const {
  const std::optional<FrictionTwoMass> p = two_mass_realization(*this);
  if (!p) return std::nullopt;
  return core::TransferFunction(Polynomial{p->damping / p->stiffness, 1.0},
                                Polynomial{1.0, a} * Polynomial{1.0, 2.0 * zeta_p * r, r * r});
}

NormalizedPlant NormalizedPlant::first_mode() const {
  NormalizedPlant first = *this;
  first.higher_modes.clear();
  return first;
}

std::optional<core::TransferFunction> NormalizedPlant::load_estimate() const {
  if (!higher_modes.empty() && !chain_load) return std::nullopt;
  const NormalizedPlant first = first_mode();
  const std::optional<core::TransferFunction> two_mass = first.load();
  if (!two_mass) return std::nullopt;
  Polynomial num = two_mass->num();
  Polynomial den = two_mass->den();
  for (const fit::Mode& m : higher_modes) {
    const double wp = m.resonance.omega_rad_s, wz = m.antiresonance.omega_rad_s;
    num = num * Polynomial{2.0 * m.antiresonance.zeta * wp * wp / wz, wp * wp};
    den = den * quadratic_polynomial(m.resonance);
  }
  return core::TransferFunction(num, den);
}

std::complex<double> NormalizedPlant::measured_response(double omega) const {
  const Complex s(0.0, omega);
  Complex p = (s * s + 2.0 * zeta_z * s + 1.0) / ((s + a) * (s * s + 2.0 * zeta_p * r * s + r * r));
  for (const fit::Mode& m : higher_modes) p *= quadratic(m.antiresonance, s) / (mode_dc_gain(m) * quadratic(m.resonance, s));
  p *= hf.response(omega);
  if (output == fit::OutputKind::kPosition) p /= s;
  return p;
}

bool NormalizedPlant::frictionless_consistent(double rel) const noexcept {
  const double frictionless = r * zeta_z;
  return std::abs(zeta_p - frictionless) <= rel * std::max(zeta_p, frictionless) && a <= rel * zeta_p * r;
}

// ---------------------------------------------------------------- normalize

NormalizedPlant normalize(const fit::PlantModel& model, const HfDynamics& hf) {
  check_rigid_and_gain(model);
  check_modes(model);
  check_lag_and_delay(model, hf);
  const std::vector<fit::Mode> modes = sorted_modes(model.modes);
  check_resonance_ratio(modes.front());

  const fit::Mode& first = modes.front();
  NormalizedPlant p;
  p.omega_z = first.antiresonance.omega_rad_s;
  p.r = first.resonance.omega_rad_s / p.omega_z;
  p.zeta_z = first.antiresonance.zeta;
  p.zeta_p = first.resonance.zeta;
  p.a = model.rigid == fit::RigidKind::kRealPole ? model.rigid_pole_rad_s / p.omega_z : 0.0;
  p.output = model.output;
  // HF asymptote of the design model (rigid + mode 1, higher modes and lag through their DC gains).
  double k = model.gain;
  for (std::size_t i = 1; i < modes.size(); ++i) {
    k *= mode_dc_gain(modes[i]);
    p.higher_modes.push_back(normalized_mode(modes[i], p.omega_z));
  }
  if (model.lag_pole_rad_s) k /= *model.lag_pole_rad_s;
  p.motor_inertia = 1.0 / k;
  p.hf = merged_hf(model, hf).time_scaled(p.omega_z);
  return p;
}

NormalizedPlant normalized_two_mass(double r, double zeta_z, std::optional<double> zeta_p, double a) {
  detail::require_ratio(r, "r");
  detail::require_non_negative(zeta_z, "zeta_z", "a damping ratio");
  if (zeta_p) detail::require_non_negative(*zeta_p, "zeta_p", "a damping ratio");
  detail::require_non_negative(a, "a", "a rigid pole");
  if (r <= kMinResonanceRatio)
    throw InputError(core::at_field("r"), "antiresonance above resonance: non-collocated or mis-fitted (r = " +
                                              show(r) + "; this tuning needs r > 1.05)");
  NormalizedPlant p;
  p.r = r;
  p.zeta_z = zeta_z;
  p.zeta_p = zeta_p.value_or(r * zeta_z);
  p.a = a;
  return p;
}

// ---------------------------------------------------------------- two-mass realization

bool FrictionTwoMass::passive() const noexcept {
  return damping >= 0.0 && motor_viscous >= 0.0 && load_viscous >= 0.0;
}

std::optional<FrictionTwoMass> two_mass_realization(const NormalizedPlant& plant) {
  if (!plant.higher_modes.empty() || !(plant.zeta_z < 1.0)) return std::nullopt;
  const double r = plant.r, zz = plant.zeta_z, zp = plant.zeta_p, a = plant.a;
  const double alpha = (a * (r * r - 1.0) + 2.0 * zz - 2.0 * zp * r) / 2.0;
  const double qa = 1.0 - zz * zz;
  const double qb = 1.0 - r * r + 2.0 * a * zz * r * r - 2.0 * a * zp * r - 2.0 * alpha * zz;
  const double qc = -alpha * alpha;
  const double root = std::sqrt(qb * qb - 4.0 * qa * qc);
  // The non-negative root of qa f² + qb f + qc (qa > 0, qc <= 0), in the cancellation-free form.
  const double f = qb <= 0.0 ? (-qb + root) / (2.0 * qa) : (2.0 * alpha * alpha) / (qb + root);
  if (!(f > 0.0) || !std::isfinite(f)) return std::nullopt;
  FrictionTwoMass m;
  m.load_inertia = m.stiffness = f;
  m.load_viscous = alpha + zz * f;
  m.damping = 2.0 * zz * f - m.load_viscous;
  m.motor_viscous = a * r * r - m.load_viscous;
  const double rounding = 1e-10 * (1.0 + f);
  for (double* v : {&m.load_viscous, &m.damping, &m.motor_viscous}) {
    if (std::abs(*v) <= rounding) *v = 0.0;
  }
  if (m.damping < 0.0) return std::nullopt;
  return m;
}

std::optional<FrictionTwoMass> physical_parameters_with_friction(const NormalizedPlant& plant) {
  std::optional<FrictionTwoMass> m = two_mass_realization(plant);
  if (m && !m->passive()) return std::nullopt;
  return m;
}

PhysicalTwoMass to_physical(const FrictionTwoMass& n, const NormalizedPlant& plant) noexcept {
  const double im = plant.motor_inertia, wz = plant.omega_z;
  PhysicalTwoMass p;
  p.motor_inertia = im;
  p.load_inertia = n.load_inertia * im;
  p.stiffness = n.stiffness * im * wz * wz;
  p.damping = n.damping * im * wz;
  p.motor_viscous = n.motor_viscous * im * wz;
  p.load_viscous = n.load_viscous * im * wz;
  return p;
}

}  // namespace servotwin::tuning
