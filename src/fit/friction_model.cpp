#include "friction_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

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

/// The load's velocity over the motor's, G = Z/(Jl s + cl + Z), with cl = 4Ml/(π|Vl|) and
/// |Vl| = |G|·|Vm|. Writing Jl s + Z = bs + jX (X = Jl ω − k/ω) and c = 4Ml/π, |Vl| = x solves
/// x²((bs + c/x)² + X²) = |Vm|²|Z|², i.e. (bs² + X²)x² + 2 bs c x + c² − |Vm|²|Z|² = 0, whose
/// positive root exists when |Vm||Z| > c; otherwise the load sticks (G = 0).
Complex load_over_motor(double omega, double vm, const ChainParameters& p) {
  const Complex z(p.bs, -p.k / omega);
  const double x_reactance = p.jl * omega - p.k / omega;
  const double c = 4.0 * p.ml / kPi;
  if (c == 0.0) return z / (Complex(0.0, p.jl * omega) + z);
  const double drive = vm * std::abs(z);
  if (drive <= std::abs(c) && c > 0.0) return 0.0;
  const double a2 = p.bs * p.bs + x_reactance * x_reactance;
  const double disc = p.bs * p.bs * c * c - a2 * (c * c - drive * drive);
  // The positive root in a form without cancellation: for c > 0 near sticking (drive → c) the
  // textbook (−bs·c + √disc)/a2 subtracts two nearly equal numbers; for c < 0 (a trial step of
  // the numerical Jacobian below the bound) the textbook form is the stable one.
  const double root = std::sqrt(std::max(disc, 0.0));
  const double x = c > 0.0 ? (drive - c) * (drive + c) / (p.bs * c + root) : (-p.bs * c + root) / a2;
  if (!(x > 0.0)) return 0.0;
  return z / (Complex(p.bs + c / x, x_reactance));
}

/// Motor encoder: the motor's describing function from the measured |Vm|, the load's by the
/// closed-form balance above; P = L/(Jm s + bv + 4Mm/(π|Vm|) + Z(1 − G)).
Complex motor_side(double omega, double vm, const ChainParameters& p) {
  const Complex s(0.0, omega), z(p.bs, -p.k / omega);
  return 1.0 / (p.jm * s + p.bv + 4.0 * p.mm / (kPi * vm) + z * (1.0 - load_over_motor(omega, vm, p)));
}

/// Load encoder: explicit. The load's describing function cl = 4Ml/(π|Vl|) comes from the
/// measured |Vl|; the load's balance (Jl s + cl)Vl = Z(Vm − Vl) gives H = Vm/Vl = 1 + (Jl s + cl)/Z,
/// hence |Vm| = |H||Vl| and the motor's cm = 4Mm/(π|Vm|); the motor's balance
/// L·T = (Jm s + bv + cm)Vm + Z(Vm − Vl) then gives P = Vl/T = L/((Jm s + bv + cm)H + Jl s + cl).
Complex load_side(double omega, double vl, const ChainParameters& p) {
  const Complex s(0.0, omega), z(p.bs, -p.k / omega);
  const double cl = 4.0 * p.ml / (kPi * vl);
  const Complex h = 1.0 + (p.jl * s + cl) / z;
  const double cm = 4.0 * p.mm / (kPi * std::abs(h) * vl);
  return 1.0 / ((p.jm * s + p.bv + cm) * h + p.jl * s + cl);
}

}  // namespace

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
  m.gain = lag / (sensor == SensorSide::kMotor ? p.jm : p.jm + p.jl);
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
  const ModalPair zeros = sensor == SensorSide::kMotor
                              ? ModalPair{std::sqrt(p.k / p.jl), p.bs / (2.0 * std::sqrt(p.k * p.jl))}
                              : ModalPair{};
  m.modes = {{zeros, {omega_n, zeta_n}}};
  return m;
}

}  // namespace servotwin::fit::detail
