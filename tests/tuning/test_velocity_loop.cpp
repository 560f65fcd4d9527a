// The PI/PID velocity loop: controller transfer functions, the two-mass plant functions, the Padé
// delay and the closed-loop functions. References: the equations of motion solved directly at
// s = jω (an independent 2×2 complex solve), closed-form Padé coefficients, block-diagram
// composition of the loop, and the printed E26 closed-loop poles.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <numbers>

#include "fixture.hpp"
#include "servotwin/tuning/velocity_loop.hpp"

namespace servotwin::tuning {
namespace {

using Complex = std::complex<double>;

const std::vector<double> kOmegas{1e-3, 0.05, 0.3, 0.99, 1.0, 1.7, 3.0, 10.0, 250.0};

double rel(Complex a, Complex b) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300}); }

TEST(VelocityLoop, PidControllerMatchesItsDefinition) {
  // C = kp + ki/s + kd s/(τs + 1), R = wp kp + ki/s + wd kd s/(τs + 1) (C7.5, C7.8).
  const PidGains g{2.5, 0.7, 1.3, 0.02, 0.6, 0.25};
  const ControllerTf c = pid_controller(g);
  for (double w : kOmegas) {
    const Complex s(0.0, w);
    EXPECT_LT(rel(c.feedback(s), g.kp + g.ki / s + g.kd * s / (g.tau * s + 1.0)), 1e-13) << w;
    EXPECT_LT(rel(c.reference(s), g.wp * g.kp + g.ki / s + g.wd * g.kd * s / (g.tau * s + 1.0)), 1e-13) << w;
  }
  EXPECT_EQ(pid_controller({2.0, 0.0}).feedback.den().degree(), 0);  // P only: no pole at 0
  EXPECT_THROW((void)pid_controller({1.0, 1.0, 1.0, 0.0}), std::invalid_argument);
}

TEST(VelocityLoop, TwoMassFunctionsSolveTheEquationsOfMotion) {
  // Im ω̇m = Tm − bm ωm − (b + k/s)(ωm − ωl), Il ω̇l = (b + k/s)(ωm − ωl) − bl ωl − Tl with Im = 1,
  // solved as a 2×2 complex system at s = jω, with the friction realization of E-fric (table 5.1).
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.06, 0.15, 0.2);
  const std::optional<FrictionTwoMass> m = physical_parameters_with_friction(plant);
  const std::optional<TwoMassTransfer> t = two_mass_transfer(plant);
  ASSERT_TRUE(m && t);
  for (double w : kOmegas) {
    const Complex s(0.0, w);
    const Complex c = m->damping + m->stiffness / s;
    Eigen::Matrix2cd a;
    a << s + m->motor_viscous + c, -c, -c, m->load_inertia * s + m->load_viscous + c;
    const Eigen::Matrix2cd g = a.inverse();  // columns: Tm, −Tl
    EXPECT_LT(rel(t->motor_from_torque.frequency_response(w), g(0, 0)), 1e-10) << w;
    EXPECT_LT(rel(t->load_from_torque.frequency_response(w), g(1, 0)), 1e-10) << w;
    EXPECT_LT(rel(t->motor_from_load_torque.frequency_response(w), -g(0, 1)), 1e-10) << w;
    EXPECT_LT(rel(t->load_from_load_torque.frequency_response(w), -g(1, 1)), 1e-10) << w;
    EXPECT_LT(rel(t->load_from_torque.frequency_response(w), plant.load()->frequency_response(w)), 1e-12) << w;
  }
  NormalizedPlant modes = plant;
  modes.higher_modes.push_back({{9.0, 0.01}, {12.0, 0.02}});
  EXPECT_FALSE(two_mass_transfer(modes).has_value());
}

TEST(VelocityLoop, PadeCoefficientsAndAccuracy) {
  // Closed forms: N = 1: (1 − sT/2)/(1 + sT/2); N = 2: (1 − sT/2 + s²T²/12)/(1 + sT/2 + s²T²/12).
  const double t = 0.4;
  const core::TransferFunction p1 = pade_delay(t, 1).normalized();
  EXPECT_NEAR(p1.num().coefficient_of_power(0), 2.0 / t, 1e-12);
  EXPECT_NEAR(p1.num().coefficient_of_power(1), -1.0, 1e-12);
  EXPECT_NEAR(p1.den().coefficient_of_power(0), 2.0 / t, 1e-12);
  const core::TransferFunction p2 = pade_delay(t, 2).normalized();
  EXPECT_NEAR(p2.num().coefficient_of_power(1), -6.0 / t, 1e-12);
  EXPECT_NEAR(p2.num().coefficient_of_power(0), 12.0 / (t * t), 1e-10);
  EXPECT_NEAR(p2.den().coefficient_of_power(1), 6.0 / t, 1e-12);
  // All-pass with phase −ωT: the N = 6 approximant's phase error stays below 1e-3 rad up to ωT = 5.
  const core::TransferFunction p6 = pade_delay(t, 6);
  for (double wt = 0.1; wt <= 5.0; wt += 0.1) {
    const Complex v = p6.frequency_response(wt / t);
    EXPECT_NEAR(std::abs(v), 1.0, 1e-12);
    EXPECT_LT(std::abs(std::arg(v * std::polar(1.0, wt))), 1e-3) << wt;
  }
  EXPECT_EQ(pade_delay(0.0, 6).den().degree(), 0);
  EXPECT_THROW((void)pade_delay(0.1, 0), std::invalid_argument);
  EXPECT_THROW((void)pade_delay(-0.1, 3), std::invalid_argument);
}

/// The E26 plant with a feedback filter, a current lag and a delay (normalized time).
NormalizedPlant plant_with_hf() {
  NormalizedPlant p = normalized_two_mass(3.0, 0.01);
  p.hf.feedback_filter_s = 0.01;
  p.hf.current_lag_s = 0.02;
  p.hf.delay_s = 0.15;
  return p;
}

TEST(VelocityLoop, FrequencyFunctionsAreTheBlockDiagram) {
  // Composition of the blocks with the delay exact: L = C F A Pm, S = 1/(1 + L), ωm/ω* = R A Pm S,
  // u/ω* = R S, ωl/ω* = R A Plm S, ωm/Tl = Gml S, ωl/Tl = Gll − Glm A C F Gml S.
  const NormalizedPlant plant = plant_with_hf();
  const PidGains g{4.634937, 0.640260, 0.8, 0.05, 0.7, 0.0};
  const VelocityLoop loop(plant, g);
  const ControllerTf k = pid_controller(g);
  const TwoMassTransfer t = *two_mass_transfer(plant);
  ASSERT_TRUE(loop.has_load());
  for (double w : kOmegas) {
    const Complex s(0.0, w);
    const Complex a = plant.hf.actuator_response(w), f = plant.hf.feedback_response(w);
    const Complex c = k.feedback(s), r = k.reference(s), pm = t.motor_from_torque(s);
    const Complex l = c * f * a * pm, sens = 1.0 / (1.0 + l);
    EXPECT_LT(rel(loop.loop_gain(w), l), 1e-11) << w;
    EXPECT_LT(rel(loop.sensitivity(w), sens), 1e-11) << w;
    EXPECT_LT(std::abs(loop.sensitivity(w) + loop.complementary(w) - 1.0), 1e-11) << w;
    EXPECT_LT(rel(loop.motor_tracking(w), r * a * pm * sens), 1e-11) << w;
    EXPECT_LT(rel(loop.effort(w), r * sens), 1e-11) << w;
    EXPECT_LT(rel(loop.load_tracking(w), r * a * t.load_from_torque(s) * sens), 1e-11) << w;
    EXPECT_LT(rel(loop.motor_from_load_torque(w), t.motor_from_load_torque(s) * sens), 1e-11) << w;
    const Complex direct = t.load_from_load_torque(s) -
                           t.load_from_torque(s) * a * c * f * t.motor_from_load_torque(s) * sens;
    EXPECT_LT(rel(loop.load_from_load_torque(w), direct), 1e-9) << w;
    EXPECT_LT(rel(loop.open_loop_load_from_load_torque(w), t.load_from_load_torque(s)), 1e-12) << w;
  }
  // Integral action: ωm/ω* → 1 and the load-torque response → 0 at DC, finite at ω = 0 itself.
  EXPECT_LT(std::abs(loop.motor_tracking(0.0) - 1.0), 1e-12);
  EXPECT_LT(std::abs(loop.load_from_load_torque(0.0)), 1e-12);
}

TEST(VelocityLoop, RationalClosedLoopAgreesWithTheExactFunctions) {
  // Without delay the rational closed loop is exact; with it, the Padé (N = 6) version agrees
  // with the exact e^{−jωT} below the loop's bandwidth (ωT <= 1.5 here, Padé phase error ~1e-9).
  NormalizedPlant plant = plant_with_hf();
  const PidGains g{4.634937, 0.640260, 0.0, 0.0, 0.6, 0.0};
  for (double delay : {0.0, 0.15}) {
    plant.hf.delay_s = delay;
    const VelocityLoop loop(plant, g);
    const ClosedLoopTransfer cl = loop.closed_loop();
    const double tol = delay == 0.0 ? 1e-11 : 1e-6;
    for (double w : {1e-3, 0.05, 0.3, 1.0, 3.0, 10.0}) {
      EXPECT_LT(rel(cl.sensitivity.frequency_response(w), loop.sensitivity(w)), tol) << w;
      EXPECT_LT(rel(cl.complementary.frequency_response(w), loop.complementary(w)), tol) << w;
      EXPECT_LT(rel(cl.motor_tracking.frequency_response(w), loop.motor_tracking(w)), tol) << w;
      EXPECT_LT(rel(cl.effort.frequency_response(w), loop.effort(w)), tol) << w;
      EXPECT_LT(rel(cl.load_tracking->frequency_response(w), loop.load_tracking(w)), tol) << w;
      EXPECT_LT(rel(cl.motor_from_load_torque->frequency_response(w), loop.motor_from_load_torque(w)), tol) << w;
      EXPECT_LT(rel(cl.load_from_load_torque->frequency_response(w), loop.load_from_load_torque(w)), tol) << w;
      const Complex u_tl = -loop.controller(w) * plant.hf.feedback_response(w) * loop.motor_from_load_torque(w);
      EXPECT_LT(rel(cl.effort_from_load_torque->frequency_response(w), u_tl), tol) << w;
    }
    EXPECT_TRUE(loop.stable());
  }
}

TEST(VelocityLoop, LoadFeedbackIsTheBlockDiagramWithTheLoadMeasured) {
  // C7.17: the controller reads ωl. Composition with the delay exact: L = C F A Plm, S = 1/(1 + L),
  // ωm/ω* = R A Pm S, ωl/ω* = R A Plm S, u/ω* = R S, ωl/Tl = Gll S (the measured output's
  // disturbance), ωm/Tl = Gml − Pm A C F Gll S; the rational closed loop (Padé delay) agrees below
  // the bandwidth, and the load loop's integral action holds ωl at ω* (DC 1) and rejects Tl from ωl.
  NormalizedPlant plant = plant_with_hf();
  const PidGains g{0.6, 0.2, 0.0, 0.0, 1.0, 0.0};
  const ControllerTf k = pid_controller(g);
  const VelocityLoop loop = VelocityLoop::load_feedback(plant, k);
  const TwoMassTransfer t = *two_mass_transfer(plant);
  ASSERT_TRUE(loop.measures_load() && loop.has_load());
  for (double w : kOmegas) {
    const Complex s(0.0, w);
    const Complex a = plant.hf.actuator_response(w), f = plant.hf.feedback_response(w);
    const Complex c = k.feedback(s), r = k.reference(s), pm = t.motor_from_torque(s), pl = t.load_from_torque(s);
    const Complex l = c * f * a * pl, sens = 1.0 / (1.0 + l);
    EXPECT_LT(rel(loop.loop_gain(w), l), 1e-11) << w;
    EXPECT_LT(rel(loop.sensitivity(w), sens), 1e-11) << w;
    EXPECT_LT(std::abs(loop.sensitivity(w) + loop.complementary(w) - 1.0), 1e-11) << w;
    EXPECT_LT(rel(loop.motor_tracking(w), r * a * pm * sens), 1e-11) << w;
    EXPECT_LT(rel(loop.load_tracking(w), r * a * pl * sens), 1e-11) << w;
    EXPECT_LT(rel(loop.effort(w), r * sens), 1e-11) << w;
    EXPECT_LT(rel(loop.load_from_load_torque(w), t.load_from_load_torque(s) * sens), 1e-10) << w;
    const Complex motor = t.motor_from_load_torque(s) - pm * a * c * f * t.load_from_load_torque(s) * sens;
    EXPECT_LT(rel(loop.motor_from_load_torque(w), motor), 1e-9) << w;
  }
  ASSERT_TRUE(loop.stable());
  const ClosedLoopTransfer cl = loop.closed_loop();
  for (double w : {1e-3, 0.05, 0.3, 1.0}) {
    EXPECT_LT(rel(cl.sensitivity.frequency_response(w), loop.sensitivity(w)), 1e-6) << w;
    EXPECT_LT(rel(cl.load_tracking->frequency_response(w), loop.load_tracking(w)), 1e-6) << w;
    EXPECT_LT(rel(cl.motor_from_load_torque->frequency_response(w), loop.motor_from_load_torque(w)), 1e-6) << w;
    EXPECT_LT(rel(cl.load_from_load_torque->frequency_response(w), loop.load_from_load_torque(w)), 1e-6) << w;
    const Complex u_tl = -loop.controller(w) * plant.hf.feedback_response(w) * loop.load_from_load_torque(w);
    EXPECT_LT(rel(cl.effort_from_load_torque->frequency_response(w), u_tl), 1e-6) << w;
  }
  EXPECT_LT(std::abs(loop.load_tracking(0.0) - 1.0), 1e-12);
  EXPECT_LT(std::abs(loop.load_from_load_torque(0.0)), 1e-12);
  NormalizedPlant modes = plant;
  modes.higher_modes.push_back({{9.0, 0.01}, {12.0, 0.02}});
  EXPECT_THROW((void)VelocityLoop::load_feedback(modes, k), std::invalid_argument);
}

TEST(VelocityLoop, E26ClosedLoopPoles) {
  // E26 (ω* = 0.30 corrected, catalog misprint 3): poles −0.3 (double) and −2.10747 ± 1.63480j.
  const NormalizedPlant plant = normalized_two_mass(3.0, 0.01);
  const VelocityLoop loop(plant, {4.634937, 0.640260});
  const std::vector<Complex> roots = test::sorted_roots(loop.closed_loop().characteristic.roots());
  ASSERT_EQ(roots.size(), 4u);
  EXPECT_NEAR(std::abs(roots[0] + 0.3), 0.0, 2e-3);  // a double root: perturbation ~ sqrt(1e-6)
  EXPECT_NEAR(std::abs(roots[1] + 0.3), 0.0, 2e-3);
  EXPECT_LT(std::abs(roots[2] - Complex(-2.10747, 1.63480)), 2e-5);
  EXPECT_TRUE(loop.stable());
  // Gains far beyond the admissible range destabilize the loop with the HF dynamics.
  EXPECT_FALSE(VelocityLoop(plant_with_hf(), {400.0, 10.0}).stable());
}

/// An undamped three-mass chain J1–k1–J2–k2–J3, torque on J1 (the motor), load J3.
struct Chain {
  Eigen::Matrix3d m = Eigen::Vector3d(1.0, 2.0, 0.5).asDiagonal();
  double k1 = 10.0, k2 = 40.0;
  [[nodiscard]] Eigen::Matrix3d stiffness() const {
    Eigen::Matrix3d k;
    k << k1, -k1, 0.0, -k1, k1 + k2, -k2, 0.0, -k2, k2;
    return k;
  }
  /// Velocities of the three masses per motor torque at s = jω.
  [[nodiscard]] Eigen::Vector3cd velocities(double w) const {
    const Complex s(0.0, w);
    const Eigen::Matrix3cd a = m.cast<Complex>() * s * s + stiffness().cast<Complex>();
    return s * a.inverse().col(0);
  }
  /// Resonances (the nonzero eigenfrequencies) and antiresonances (the chain with the motor
  /// clamped), ascending [rad/s].
  [[nodiscard]] std::pair<Eigen::Vector2d, Eigen::Vector2d> frequencies() const {
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> all(stiffness(), m);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> clamped(stiffness().bottomRightCorner<2, 2>(),
                                                                      m.bottomRightCorner<2, 2>());
    return {all.eigenvalues().tail<2>().cwiseSqrt(), clamped.eigenvalues().cwiseSqrt()};
  }
};

TEST(VelocityLoop, ChainLoadEstimateIsExactForAnUndampedChain) {
  // Reference: the chain's equations of motion solved at s = jω. Undamped, the load follows the
  // motor as ωl/ωm = N(0)/N(s) with N the clamped-motor polynomial, which is what the estimate's
  // per-mode couplings multiply out to; the motor model itself is the chain's exact motor response.
  const Chain chain;
  const auto [poles, zeros] = chain.frequencies();
  fit::PlantModel model;
  model.rigid = fit::RigidKind::kIntegrator;
  model.gain = 1.0;  // 1/J1
  model.modes = {{{zeros(0), 0.0}, {poles(0), 0.0}}, {{zeros(1), 0.0}, {poles(1), 0.0}}};
  NormalizedPlant plant = normalize(model);
  EXPECT_FALSE(plant.load_estimate().has_value());  // higher modes, not declared a chain
  plant.chain_load = true;
  const std::optional<core::TransferFunction> load = plant.load_estimate();
  ASSERT_TRUE(load.has_value());
  const core::TransferFunction motor = plant.motor(true);
  for (double w : {0.05, 0.3, 0.7, 1.4, 2.5, 4.0, 9.0}) {
    const Eigen::Vector3cd v = chain.velocities(w * plant.omega_z);
    EXPECT_LT(rel(load->frequency_response(w) / motor.frequency_response(w), v(2) / v(0)), 1e-9) << w;
  }
  // The loop's load tracking is its motor tracking through the same ratio (block diagram).
  const VelocityLoop loop(plant, {2.0, 0.5});
  EXPECT_TRUE(loop.has_load_tracking());
  EXPECT_FALSE(loop.has_load());
  EXPECT_TRUE(std::isnan(loop.load_from_load_torque(1.0).real()));
  for (double w : {0.3, 1.4, 4.0}) {
    const Complex ratio = load->frequency_response(w) / motor.frequency_response(w);
    EXPECT_LT(rel(loop.load_tracking(w), loop.motor_tracking(w) * ratio), 1e-10) << w;
    EXPECT_LT(rel(loop.responses(w).load_tracking, loop.load_tracking(w)), 1e-12) << w;
  }
  EXPECT_EQ(loop.characteristic_polynomial().coefficients().size(), loop.closed_loop().characteristic.coefficients().size());
  for (std::size_t i = 0; i < loop.characteristic_polynomial().coefficients().size(); ++i)
    EXPECT_EQ(loop.characteristic_polynomial().coefficients()[i], loop.closed_loop().characteristic.coefficients()[i]);
  ASSERT_TRUE(loop.closed_loop().load_tracking.has_value());
  EXPECT_LT(rel(loop.closed_loop().load_tracking->frequency_response(0.7), loop.load_tracking(0.7)), 1e-6);
}

TEST(VelocityLoop, HigherModesHaveNoLoadSide) {
  NormalizedPlant plant = normalized_two_mass(2.0, 0.02);
  plant.higher_modes.push_back({{6.0, 0.01}, {12.0, 0.02}});
  const VelocityLoop full(plant, {2.0, 0.5});
  EXPECT_FALSE(full.has_load());
  EXPECT_FALSE(full.has_load_tracking());
  EXPECT_TRUE(std::isnan(full.load_tracking(1.0).real()));
  EXPECT_FALSE(full.closed_loop().load_tracking.has_value());
  EXPECT_EQ(full.closed_loop().characteristic.degree(), 6);
  const VelocityLoop first_mode(plant, {2.0, 0.5}, true, false);
  EXPECT_TRUE(first_mode.has_load());
  EXPECT_EQ(first_mode.closed_loop().characteristic.degree(), 4);
}

}  // namespace
}  // namespace servotwin::tuning
