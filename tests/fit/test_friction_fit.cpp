// The two-mass fit with Coulomb friction (fit/friction_fit.hpp, issue 25 §1).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include "servotwin/fit/fit.hpp"
#include "servotwin/fit/friction_fit.hpp"

namespace servotwin::fit {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace friction_test {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;

/// The motor bench's mechanics (machine preset "motor-bench"): antiresonance 53 Hz, resonance
/// 76 Hz, ζz 0.02, viscous 3e-4 N m s/rad in all (rigid pole 0.0048 Hz), current loop 0.2 ms.
struct Bench {
  double jm = 0.0048146, jl = 0.0050854, k = 563.95, bs = 0.06774, bv = 3e-4;
  double mm = 0.0, ml = 0.0;
  PlantModel actuator() const {
    PlantModel m;
    m.lag_pole_rad_s = 1.0 / 2e-4;
    return m;
  }
};

Complex lag(double omega) { return 5000.0 / Complex(5000.0, omega); }

/// The two-mass chain's equations written as a 2×2 system (C3.12), with extra viscous terms cm, cl
/// on motor and load: [Jm s + bv + cm + Z, −Z; −Z, Jl s + cl + Z] [Vm; Vl] = [L(s); 0],
/// Z = bs + k/s. Returns (Vm, Vl) per unit torque.
std::pair<Complex, Complex> chain(const Bench& b, double omega, double cm, double cl) {
  const Complex s(0.0, omega);
  const Complex z = b.bs + b.k / s;
  Eigen::Matrix2cd a;
  a << b.jm * s + b.bv + cm + z, -z, -z, b.jl * s + cl + z;
  const Eigen::Vector2cd v = a.partialPivLu().solve(Eigen::Vector2cd(lag(omega), 0.0));
  return {v[0], v[1]};
}

/// Harmonic balance by brute force: given the torque amplitude T, iterate the describing functions
/// cm = 4Mm/(π|Vm|), cl = 4Ml/(π|Vl|) on the amplitudes of the previous solution (damped) until they
/// settle. Returns Vm/T and |Vm|.
std::pair<Complex, double> harmonic_balance(const Bench& b, double omega, double torque) {
  auto [vm, vl] = chain(b, omega, 0.0, 0.0);
  double am = std::abs(vm) * torque, al = std::abs(vl) * torque;
  for (int i = 0; i < 20000; ++i) {
    const auto [m, l] = chain(b, omega, 4.0 * b.mm / (kPi * am), 4.0 * b.ml / (kPi * al));
    const double am_next = std::sqrt(am * std::abs(m) * torque), al_next = std::sqrt(al * std::abs(l) * torque);
    vm = m;
    if (std::abs(am_next - am) < 1e-15 * am && std::abs(al_next - al) < 1e-15 * al) break;
    am = am_next;
    al = al_next;
  }
  return {vm, am};
}

TEST(FrictionFit, WithoutFrictionTheResponseIsTheChains) {
  // Reference: the 2×2 chain equations solved directly.
  const Bench b;
  for (double f : {0.5, 10.0, 53.0, 76.0, 400.0}) {
    const double w = 2.0 * kPi * f;
    const Complex expected = chain(b, w, 0.0, 0.0).first;
    const Complex got = coulomb_two_mass_response(w, 1.0, b.jm, b.jl, b.k, b.bs, b.bv, 0.0, 0.0, b.actuator());
    EXPECT_LT(std::abs(got / expected - 1.0), 1e-12) << f << " Hz";
  }
}

TEST(FrictionFit, TheClosedFormLoadAmplitudeIsTheHarmonicBalance) {
  // Reference: the brute-force iteration of both describing functions above, at a torque
  // amplitude; the closed form takes the motor amplitude that iteration found (as the fit takes
  // the measured one). Below, at and above the antiresonance, and with a sticking load.
  Bench b;
  b.mm = 0.3;
  b.ml = 0.2;
  for (double f : {2.0, 30.0, 53.0, 60.0, 150.0}) {
    const double w = 2.0 * kPi * f;
    const auto [expected, vm] = harmonic_balance(b, w, 2.0);
    const Complex got = coulomb_two_mass_response(w, vm, b.jm, b.jl, b.k, b.bs, b.bv, b.mm, b.ml, b.actuator());
    EXPECT_LT(std::abs(got / expected - 1.0), 1e-9) << f << " Hz";
  }
  // A load whose friction exceeds what the shaft can pass at this motor amplitude stands still:
  // the motor then sees the shaft as a spring to the frame.
  b.ml = 50.0;
  const double w = 2.0 * kPi * 5.0;
  const Complex s(0.0, w);
  const Complex clamped = lag(w) / (b.jm * s + b.bv + 4.0 * b.mm / (kPi * 0.01) + b.bs + b.k / s);
  const Complex got = coulomb_two_mass_response(w, 0.01, b.jm, b.jl, b.k, b.bs, b.bv, b.mm, b.ml, b.actuator());
  EXPECT_LT(std::abs(got / clamped - 1.0), 1e-12);
}

/// A swept-sine response of the bench with friction, made by the brute-force harmonic balance at
/// torque amplitudes that rise towards low frequencies as an amplitude adaptation would, with
/// 0.5 % complex noise; each point carries its amplitude.
core::FrequencyResponse measured(const Bench& b, unsigned seed) {
  core::FrequencyResponse r;
  r.quality_kind = core::QualityKind::kThd;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.005 / std::sqrt(2.0));
  for (int i = 0; i < 70; ++i) {
    const double f = 1.5 * std::pow(300.0 / 1.5, i / 69.0);
    const double torque = 1.12 * (1.0 + 3.0 / f);
    const Complex p = harmonic_balance(b, 2.0 * kPi * f, torque).first;
    core::FrequencyPoint q;
    q.freq_hz = f;
    q.value = p * Complex(1.0 + noise(rng), noise(rng));
    q.amplitude = torque;
    r.points.push_back(q);
  }
  return r;
}

/// The fits the friction fit starts from: two-mass with the lag (the bench has a current loop).
FitOptions with_lag() {
  FitOptions o;
  o.lag = true;
  return o;
}
FitReport linear_fit(const core::FrequencyResponse& r) { return fit_plant(r, {ModelRequest::Kind::kTwoMass, 1}, with_lag()); }

TEST(FrictionFit, RecoversFrictionAndTheLinearDampingFromOneMeasurement) {
  // Reference: the parameters the data were made with (the brute-force harmonic balance above).
  // Friction at 0.5 and 0.35 of the high-frequency excitation amplitude: the linear fit reads it as
  // a rigid pole (rms log error 0.61), the friction fit must give the true values back within
  // what 0.5 % noise allows.
  Bench b;
  b.mm = 0.56;
  b.ml = 0.4;
  const double wz = std::sqrt(b.k / b.jl), zeta_z = b.bs / (2.0 * std::sqrt(b.k * b.jl));
  for (unsigned seed : {1u, 2u}) {
    const core::FrequencyResponse r = measured(b, seed);
    const FitOptions o = with_lag();
    const FitReport linear = linear_fit(r);
    EXPECT_GT(linear.result.model.rigid_pole_rad_s, 100.0 * b.bv / (b.jm + b.jl));  // friction read as viscous
    const CoulombFit c = fit_coulomb_friction(r, linear, o);
    ASSERT_TRUE(c.fitted) << c.note;
    // Within four of the fit's own standard deviations, and those small: 0.5 % noise on 70
    // points (measured: ζz ± 3.7 %, ωz ± 0.1 %, friction levels ± 0.2 %).
    const Mode& m = c.model.modes.front();
    const auto within = [](const Estimate& e, double truth, double max_relative_std) {
      EXPECT_NEAR(e.value, truth, 4.0 * e.std);
      EXPECT_LT(e.std, max_relative_std * truth);
    };
    within(c.motor_coulomb, b.mm, 0.01);
    within(c.load_coulomb, b.ml, 0.01);
    within({m.antiresonance.omega_rad_s, c.mode.antiresonance_omega.std}, wz, 0.002);
    within({m.antiresonance.zeta, c.mode.antiresonance_zeta.std}, zeta_z, 0.06);
    EXPECT_LT(c.model.rigid == RigidKind::kRealPole ? c.model.rigid_pole_rad_s : 0.0, 0.1);  // true 0.03 rad/s
    EXPECT_NEAR(c.motor_inertia.value, b.jm, 0.01 * b.jm);
    EXPECT_LT(c.rms_log_error, 0.5 * c.linear_rms_log_error);
    // The written report carries the linear part with its physical reading.
    const FitReport w = with_friction_model(linear, c);
    EXPECT_EQ(w.result.model.modes.front().antiresonance.zeta, m.antiresonance.zeta);
    ASSERT_TRUE(w.result.physical.parameters);
    EXPECT_EQ(w.result.physical.parameters->load_inertia.value, c.load_inertia.value);
  }
}

TEST(FrictionFit, WithoutFrictionItFindsNoneAndChangesNothing) {
  // Reference: the frictionless bench; the friction fit must find levels compatible with 0 and
  // the linear fit's modes.
  const Bench b;
  const core::FrequencyResponse r = measured(b, 3);
  const FitOptions o = with_lag();
  const FitReport linear = linear_fit(r);
  const CoulombFit c = fit_coulomb_friction(r, linear, o);
  ASSERT_TRUE(c.fitted) << c.note;
  EXPECT_LT(c.motor_coulomb.value, 3.0 * c.motor_coulomb.std + 1e-3);
  EXPECT_LT(c.load_coulomb.value, 3.0 * c.load_coulomb.std + 1e-3);
  EXPECT_NEAR(c.model.modes.front().antiresonance.zeta, linear.result.model.modes.front().antiresonance.zeta,
              0.05 * linear.result.model.modes.front().antiresonance.zeta);
}

TEST(FrictionFit, SaysWhyItCannotFit) {
  Bench b;
  core::FrequencyResponse r = measured(b, 4);
  const FitOptions o = with_lag();
  const FitReport linear = linear_fit(r);
  r.points[5].amplitude = 0.0;  // e.g. a broadband estimate: no amplitude per point
  const CoulombFit c = fit_coulomb_friction(r, linear, o);
  EXPECT_FALSE(c.fitted);
  EXPECT_NE(c.note.find("no excitation amplitude"), std::string::npos) << c.note;
  const FitReport rigid = fit_plant(r, {ModelRequest::Kind::kModes, 0}, o);
  EXPECT_NE(fit_coulomb_friction(r, rigid, o).note.find("no two-mass parameters"), std::string::npos);
}

TEST(FrictionFit, LagDoesNotEnterTheMotorInertia) {
  // Reference: C3.12 with K the high-frequency asymptote of the mechanics; with a lag
  // 1/(s + p) the model's gain is p/Jm (the lag's DC gain 1/p belongs to the gain).
  const Bench b;
  const core::FrequencyResponse r = measured(b, 5);
  const FitReport linear = linear_fit(r);
  ASSERT_TRUE(linear.result.physical.parameters);
  EXPECT_NEAR(linear.result.physical.parameters->motor_inertia.value, b.jm, 0.01 * b.jm);
  EXPECT_NEAR(linear.result.physical.parameters->stiffness.value, b.k, 0.01 * b.k);
}

}  // namespace friction_test
}  // namespace
}  // namespace servotwin::fit
