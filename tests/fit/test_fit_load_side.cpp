// Load-side (non-collocated) responses: the model family with resonances alone (plant_model.hpp,
// FitOptions::sensor, issue 25 §1 "both encoder sides — the load side has no antiresonance, so
// there the resonance alone"). References: the two-mass chain's load velocity over the torque
// solved as its 2×2 system (C3.12), and the chain's closed forms ωp² = k(Jm + Jl)/(Jm Jl),
// 2ζp ωp = b(Jm + Jl)/(Jm Jl).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include "servotwin/core/error.hpp"
#include "servotwin/core/frequency_response.hpp"
#include "servotwin/fit/fit.hpp"

namespace servotwin::fit {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace load_side_test {

using Complex = std::complex<double>;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// The motor bench's mechanics (53/76 Hz) with a 0.2 ms current loop and viscous friction bv on
/// the motor.
struct Chain {
  double jm = 0.0048146, jl = 0.0050854, k = 563.95, b = 0.06774, bv = 3e-4, lag = 5000.0;
  [[nodiscard]] double omega_p() const { return std::sqrt(k * (jm + jl) / (jm * jl)); }
  [[nodiscard]] double zeta_p() const { return b * (jm + jl) / (jm * jl) / (2.0 * omega_p()); }
  /// (motor, load) velocity per unit torque at s = jω, from [Jm s + bv + Z, −Z; −Z, Jl s + Z].
  [[nodiscard]] std::pair<Complex, Complex> velocities(double omega) const {
    const Complex s(0.0, omega), z = b + k / s;
    Eigen::Matrix2cd a;
    a << jm * s + bv + z, -z, -z, jl * s + z;
    const Eigen::Vector2cd v = a.partialPivLu().solve(Eigen::Vector2cd(lag / (s + lag), 0.0));
    return {v[0], v[1]};
  }
};

core::FrequencyResponse load_response(const Chain& c, double noise, unsigned seed) {
  core::FrequencyResponse r;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise / std::sqrt(2.0));
  for (double f : core::log_space(1.0, 500.0, 80)) {
    core::FrequencyPoint p;
    p.freq_hz = f;
    p.value = c.velocities(kTwoPi * f).second * Complex(1.0 + n(rng), n(rng));
    r.points.push_back(p);
  }
  return r;
}

FitOptions load_options() {
  FitOptions o;
  o.sensor = SensorSide::kLoad;
  o.output = OutputChoice::kVelocity;
  o.lag = true;
  return o;
}

TEST(LoadSide, TheModelIsTheChainsLoadVelocity) {
  // Without viscous friction on the motor (an integrator) the load side of the chain is exactly
  // K/s · (2ζω s + ω²)/(s² + 2ζω s + ω²) · p/(s + p), K = 1/(Jm + Jl) (plant_model.hpp).
  Chain c;
  c.bv = 0.0;
  PlantModel m;
  m.sensor = SensorSide::kLoad;
  m.rigid = RigidKind::kIntegrator;
  m.gain = c.lag / (c.jm + c.jl);
  m.lag_pole_rad_s = c.lag;
  m.modes = {Mode{{}, {c.omega_p(), c.zeta_p()}}};
  for (double f : {0.5, 10.0, 53.0, 76.0, 400.0, 3000.0}) {
    const double w = kTwoPi * f;
    const Complex expected = c.velocities(w).second;
    EXPECT_LT(std::abs(m.response(w) / expected - 1.0), 1e-10) << f << " Hz";
    EXPECT_LT(std::abs(m.transfer_function()(Complex(0.0, w)) / expected - 1.0), 1e-10) << f << " Hz";
  }
  EXPECT_EQ(m.parameter_count(), 4u);  // K, ωp, ζp, τ2 (an integrator has no rigid pole)
}

TEST(LoadSide, FitsTheResonanceWhereTheMotorSideModelFindsNoAntiresonance) {
  const Chain c;
  for (unsigned seed : {1u, 2u, 3u}) {
    const core::FrequencyResponse r = load_response(c, 0.01, seed);
    // The collocated family has no member for it and says what to do.
    FitOptions motor = load_options();
    motor.sensor = SensorSide::kMotor;
    try {
      fit_plant(r, {ModelRequest::Kind::kTwoMass, 1}, motor);
      ADD_FAILURE() << "the motor-side fit of a load-side response should fail";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("load-side response"), std::string::npos) << e.what();
    }
    const FitReport f = fit_plant(r, {ModelRequest::Kind::kTwoMass, 1}, load_options());
    ASSERT_TRUE(f.result.converged) << f.result.message;
    ASSERT_EQ(f.result.model.modes.size(), 1u);
    EXPECT_EQ(f.result.model.sensor, SensorSide::kLoad);
    const ModeUncertainty& u = f.result.mode_estimates.front();
    // Within 4 of its standard deviations of the truth, and within §1's 0.5 % and 20 %.
    EXPECT_NEAR(u.resonance_omega.value, c.omega_p(), 4.0 * u.resonance_omega.std) << seed;
    EXPECT_NEAR(u.resonance_zeta.value, c.zeta_p(), 4.0 * u.resonance_zeta.std) << seed;
    EXPECT_NEAR(u.resonance_omega.value / c.omega_p(), 1.0, 0.005);
    EXPECT_NEAR(u.resonance_zeta.value / c.zeta_p(), 1.0, 0.2);
    EXPECT_TRUE(std::isnan(u.antiresonance_omega.value));
    // K' = K/τ2 is 1/(Jm + Jl): the total inertia, which the note reports; no split.
    EXPECT_NEAR(f.result.lag_pole_rad_s.value / f.result.gain.value, c.jm + c.jl, 0.01 * (c.jm + c.jl));
    EXPECT_FALSE(f.result.physical.parameters);
    EXPECT_NE(f.result.physical.note.find("total inertia"), std::string::npos) << f.result.physical.note;
    EXPECT_LT(f.result.rms_log_error, 0.015);  // 1 % noise
  }
}

TEST(LoadSide, AutomaticOrderSelectionCountsResonances) {
  // Reference: the one-mode chain; BIC must not add a second resonance to 1 % noise.
  const FitReport f = fit_plant(load_response(Chain{}, 0.01, 4), {ModelRequest::Kind::kAuto, 0}, load_options());
  EXPECT_EQ(f.result.model.modes.size(), 1u) << f.selection.criterion;
}

TEST(LoadSide, ConsumersThatNeedTheAntiresonanceRefuseIt) {
  PlantModel m;
  m.sensor = SensorSide::kLoad;
  m.modes = {Mode{{}, {400.0, 0.03}}};
  try {
    require_motor_side(m, "controller tuning (C7)");
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("load-side"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("controller tuning"), std::string::npos) << e.what();
  }
  m.sensor = SensorSide::kMotor;
  EXPECT_NO_THROW(require_motor_side(m, "x"));
}

}  // namespace load_side_test
}  // namespace
}  // namespace servotwin::fit
