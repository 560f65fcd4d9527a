#include "friction_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "servotwin/core/polynomial.hpp"

namespace servotwin::fit::detail {

namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;

/// The lag p/(s + p) (unity at DC: PlantModel's 1/(s + p) with the gain's factor p moved into the
/// inertia) and delay, at s = jω.
Complex actuator_response(const PlantModel& m, double omega) {
  const Complex s(0.0, omega);
  Complex a = 1.0;
  if (m.lag_pole_rad_s) a *= *m.lag_pole_rad_s / (s + *m.lag_pole_rad_s);
  if (m.delay_s) a *= std::polar(1.0, -omega * *m.delay_s);
  return a;
}

/// The motor's velocity and the first shaft's force, per unit load velocity.
struct MotorEnd {
  Complex velocity, force;
};

/// Walks the chain from the load to the motor at s: the load moves with velocity 1 against its
/// inertia and the describing function `cl` of its friction; each shaft i (impedance
/// bi + ki/s) carries the force of everything beyond it, so the next mass inward moves by that
/// force over the shaft's impedance more. With `load_held` the load stands still (it sticks) and
/// the last shaft carries a unit force instead. Both results are affine in cl.
MotorEnd walk_to_motor(Complex s, const ChainParameters& p, double cl, bool load_held) {
  const std::size_t n = p.shafts();
  Complex u = load_held ? 0.0 : 1.0;
  Complex f = load_held ? Complex(1.0) : (p.inertia[n] * s + cl) * u;
  for (std::size_t i = n; i-- > 0;) {
    u += f / (p.damping[i] + p.stiffness[i] / s);
    if (i == 0) break;
    f += p.inertia[i] * s * u;
  }
  return {u, f};
}

/// The load's velocity amplitude x = |Vl| for a measured motor amplitude |Vm|. The walk gives
/// Vm/Vl = A + B·cl with cl = c/x (c = 4Ml/π), so x|A + Bc/x| = |Vm|, i.e.
/// |A|²x² + 2Re(A B̄)c x + |B|²c² − |Vm|² = 0, whose positive root exists when |Vm| > |B|c;
/// otherwise the load sticks (nullopt). For one shaft |B| = 1/|Z|: the load breaks away when the
/// shaft's force |Vm||Z| exceeds its friction.
std::optional<double> load_amplitude(Complex s, double vm, const ChainParameters& p, double c) {
  const Complex a = walk_to_motor(s, p, 0.0, false).velocity;
  const Complex b = walk_to_motor(s, p, 1.0, false).velocity - a;
  const double a2 = std::norm(a), beta = (a * std::conj(b)).real() * c, gamma = std::norm(b) * c * c - vm * vm;
  const double disc = beta * beta - a2 * gamma;
  if (gamma >= 0.0) {
    // |Vm| ≤ |B|c: sticks for c > 0; for c < 0 (a trial step of the numerical Jacobian below the
    // bound) the larger root.
    if (c > 0.0 || disc < 0.0) return std::nullopt;
    const double x = (-beta + std::sqrt(disc)) / a2;
    return x > 0.0 ? std::optional<double>(x) : std::nullopt;
  }
  // The positive root without cancellation: x = −γ/(β + √disc) (√disc > |β| when γ < 0).
  const double x = -gamma / (beta + std::sqrt(disc));
  return x > 0.0 && std::isfinite(x) ? std::optional<double>(x) : std::nullopt;
}

/// Motor encoder: the motor's describing function from the measured |Vm|, the load's by the
/// closed-form balance above; P = L·Vm/((J1 s + bv + 4Mm/(π|Vm|))Vm + F1), F1 the first shaft's
/// force.
Complex motor_side(double omega, double vm, const ChainParameters& p) {
  const Complex s(0.0, omega);
  const double c = 4.0 * p.ml / kPi;
  std::optional<double> x;
  if (c != 0.0) x = load_amplitude(s, vm, p, c);
  const MotorEnd e = c == 0.0 ? walk_to_motor(s, p, 0.0, false)
                     : x      ? walk_to_motor(s, p, c / *x, false)
                              : walk_to_motor(s, p, 0.0, true);
  return 1.0 / (p.inertia[0] * s + p.bv + 4.0 * p.mm / (kPi * vm) + e.force / e.velocity);
}

/// Load encoder: explicit. The load's describing function cl = 4Ml/(π|Vl|) comes from the
/// measured |Vl|; the walk gives Vm/Vl and with it |Vm| and the motor's cm = 4Mm/(π|Vm|); the
/// motor's balance L·T = (J1 s + bv + cm)Vm + F1 then gives P = Vl/T.
Complex load_side(double omega, double vl, const ChainParameters& p) {
  const Complex s(0.0, omega);
  const MotorEnd e = walk_to_motor(s, p, 4.0 * p.ml / (kPi * vl), false);
  const double cm = 4.0 * p.mm / (kPi * std::abs(e.velocity) * vl);
  return 1.0 / ((p.inertia[0] * s + p.bv + cm) * e.velocity + e.force);
}

/// The linear chain's polynomials: the walk with cl = 0 in s, each step's shaft impedance
/// (bi s + ki)/s cleared by multiplying through with bi s + ki. Vm/Vl = U/Q, F1/Vl = F/Q with Q = Π(bi s + ki): the motor-side admittance is
/// U/((J1 s + bv)U + F), the load side's Q/((J1 s + bv)U + F).
struct ChainPolynomials {
  core::Polynomial u, f, q;
};

ChainPolynomials chain_polynomials(const ChainParameters& p) {
  const std::size_t n = p.shafts();
  const core::Polynomial s{1.0, 0.0};
  ChainPolynomials c{core::Polynomial{1.0}, core::Polynomial{p.inertia[n], 0.0}, core::Polynomial{1.0}};
  for (std::size_t i = n; i-- > 0;) {
    const core::Polynomial shaft{p.damping[i], p.stiffness[i]};
    c.u = c.u * shaft + c.f * s;
    c.q = c.q * shaft;
    if (i == 0) {
      c.f = c.f * shaft;
      break;
    }
    c.f = c.f * shaft + p.inertia[i] * (s * c.u);
  }
  return c;
}

/// Complex roots as modal pairs; real roots paired in ascending order (an overdamped pair:
/// ω² = their product, 2ζω = −their sum). Ascending frequency.
std::vector<ModalPair> modal_pairs(const std::vector<Complex>& roots) {
  std::vector<ModalPair> pairs;
  std::vector<double> real;
  for (const Complex& r : roots) {
    if (r.imag() > 0.0) pairs.push_back({std::abs(r), -r.real() / std::abs(r)});
    if (r.imag() == 0.0) real.push_back(r.real());
  }
  std::sort(real.begin(), real.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  for (std::size_t i = 0; i + 1 < real.size(); i += 2) {
    const double omega = std::sqrt(real[i] * real[i + 1]);
    pairs.push_back({omega, -(real[i] + real[i + 1]) / (2.0 * omega)});
  }
  std::sort(pairs.begin(), pairs.end(), [](const ModalPair& a, const ModalPair& b) { return a.omega_rad_s < b.omega_rad_s; });
  return pairs;
}

/// Coefficients (highest first) of Π(s² + ω²), times s when `odd`: core::Polynomial::from_roots of
/// the pairs ±jω multiplies real quadratics s² + 0·s + ω², so the odd (even) powers' coefficients
/// are exact zeros, the parity the continued fraction relies on.
std::vector<double> even_polynomial(const std::vector<double>& omega, bool odd) {
  std::vector<Complex> roots;
  for (double w : omega) {
    roots.emplace_back(0.0, w);
    roots.emplace_back(0.0, -w);
  }
  core::Polynomial p = core::Polynomial::from_roots(roots);
  if (odd) p = p * core::Polynomial{1.0, 0.0};
  return {p.coefficients().begin(), p.coefficients().end()};
}

}  // namespace

double ChainParameters::total_inertia() const noexcept { return std::accumulate(inertia.begin(), inertia.end(), 0.0); }

ChainParameters two_mass_chain(double jm, double jl, double k, double bs, double bv, double mm, double ml) {
  return {{jm, jl}, {k}, {bs}, bv, mm, ml};
}

std::complex<double> chain_response(double omega, double velocity_amplitude, const ChainParameters& p,
                                    const PlantModel& actuator, SensorSide sensor) {
  Complex r = actuator_response(actuator, omega) *
              (sensor == SensorSide::kMotor ? motor_side(omega, velocity_amplitude, p) : load_side(omega, velocity_amplitude, p));
  if (actuator.output == OutputKind::kPosition) r /= Complex(0.0, omega);
  return r;
}

PlantModel chain_linear_part(const ChainParameters& p, const PlantModel& actuator, RigidKind rigid, SensorSide sensor) {
  PlantModel m;
  m.output = actuator.output;
  m.sensor = sensor;
  m.lag_pole_rad_s = actuator.lag_pole_rad_s;
  m.delay_s = actuator.delay_s;
  const double lag = actuator.lag_pole_rad_s ? *actuator.lag_pole_rad_s : 1.0;
  m.gain = lag / (sensor == SensorSide::kMotor ? p.inertia[0] : p.total_inertia());
  const ChainPolynomials c = chain_polynomials(p);
  const core::Polynomial den = core::Polynomial{p.inertia[0], p.bv} * c.u + c.f;
  // The rigid pole is the real root nearest 0 (exactly 0 when bv = 0); the rest form the modes.
  std::vector<Complex> roots = den.roots();
  std::sort(roots.begin(), roots.end(), [](Complex x, Complex y) { return std::abs(x) < std::abs(y); });
  const auto rigid_root = std::find_if(roots.begin(), roots.end(), [](Complex x) { return x.imag() == 0.0; });
  const double rigid_pole = rigid_root != roots.end() ? -rigid_root->real() : 0.0;
  if (rigid_root != roots.end()) roots.erase(rigid_root);
  m.rigid = rigid == RigidKind::kIntegrator || p.bv == 0.0 ? RigidKind::kIntegrator : RigidKind::kRealPole;
  m.rigid_pole_rad_s = m.rigid == RigidKind::kRealPole ? rigid_pole : 0.0;
  const std::vector<ModalPair> poles = modal_pairs(roots);
  const std::vector<ModalPair> zeros = sensor == SensorSide::kMotor ? modal_pairs(c.u.roots()) : std::vector<ModalPair>{};
  for (std::size_t i = 0; i < poles.size(); ++i) m.modes.push_back({i < zeros.size() ? zeros[i] : ModalPair{}, poles[i]});
  return m;
}

std::optional<ChainParameters> chain_of_modes(const std::vector<Mode>& modes, double gain, std::string& why) {
  if (modes.empty() || !(gain > 0.0)) {
    why = "no flexible mode or no positive gain";
    return std::nullopt;
  }
  // Frequencies in units of the first antiresonance keep the coefficients near one.
  const double unit = modes.front().antiresonance.omega_rad_s;
  std::vector<double> wz, wp;
  for (const Mode& m : modes) {
    wz.push_back(m.antiresonance.omega_rad_s / unit);
    wp.push_back(m.resonance.omega_rad_s / unit);
  }
  // Z(s) = (unit/K)·s̃Π(s̃² + ω̃p²)/Π(s̃² + ω̃z²) with s = unit·s̃: each step takes the leading
  // term e·s̃ of num/den (an inertia J = e/unit in an impedance step, a compliance 1/k = e/unit in
  // an admittance step) and continues with den/(num − e·s̃·den), whose two leading coefficients
  // vanish (the first by construction, the second by parity).
  std::vector<double> num = even_polynomial(wp, true), den = even_polynomial(wz, false);
  for (double& x : num) x *= unit / gain;
  const std::size_t n = modes.size();
  ChainParameters chain;
  for (std::size_t step = 0; step <= 2 * n; ++step) {
    const double e = num.front() / den.front();
    if (!(e > 0.0) || !std::isfinite(e)) {
      why = "the modes do not interlace as a mass chain's (its element " + std::to_string(step + 1) + " is not positive)";
      return std::nullopt;
    }
    if (step % 2 == 0)
      chain.inertia.push_back(e / unit);
    else
      chain.stiffness.push_back(unit / e);
    if (step == 2 * n) break;
    std::vector<double> rest(den.size() - 1);
    for (std::size_t i = 0; i < rest.size(); ++i) rest[i] = num[i + 2] - (i + 2 < den.size() ? e * den[i + 2] : 0.0);
    num = std::move(den);
    den = std::move(rest);
  }
  for (std::size_t i = 0; i < n; ++i)
    chain.damping.push_back(2.0 * modes[i].resonance.zeta * chain.stiffness[i] / modes[i].resonance.omega_rad_s);
  return chain;
}

}  // namespace servotwin::fit::detail
