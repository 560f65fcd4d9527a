// Normalization of fitted plant models and the two-mass realization with friction (catalog §0,
// C7.2, C7.6, C7.16). Expected values: the catalog's E24 demo plant (printed
// Im = 1, Il = 8, b = 0.2, k = 8 and [V] ωz = 1, ξz = 0.0125, ωn = 3, ξ = 0.0375); the plan's
// E-fric row ([R]: f = 8.06307520, bl = 0.89378451, b = 0.07378451, bm = 0.90621549); the
// table-5.1 preset's physical realization (include/servotwin/machine/flexible_presets.hpp, derived
// there from the C3.12 coefficient equations); tests/data/tuning/tuning_reference.json (fsolve on
// the coefficient equations, tools/reference/tuning_reference.py); and model responses computed
// by fit::PlantModel itself (an independent evaluation of the same plant).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>

#include "fixture.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/fit/plant_model.hpp"
#include "servotwin/tuning/normalized_plant.hpp"

namespace servotwin::tuning {
namespace {

using core::Polynomial;
using test::reference;
using test::rel_diff;

fit::PlantModel two_mass_model(double gain, fit::RigidKind rigid, double a, fit::ModalPair zeros, fit::ModalPair poles) {
  fit::PlantModel m;
  m.gain = gain;
  m.rigid = rigid;
  m.rigid_pole_rad_s = a;
  m.modes = {{zeros, poles}};
  return m;
}

/// E24's demo plant: (1/s)(s² + 0.025 s + 1)/(s² + 0.225 s + 9), Im = 1.
fit::PlantModel e24_model() { return two_mass_model(1.0, fit::RigidKind::kIntegrator, 0.0, {1.0, 0.0125}, {3.0, 0.0375}); }
/// Table 5.1: (0.5/(s + 0.2))(s² + 0.12 s + 1)/(s² + 0.9 s + 9).
fit::PlantModel table51_model() { return two_mass_model(0.5, fit::RigidKind::kRealPole, 0.2, {1.0, 0.06}, {3.0, 0.15}); }

/// A three-mode position plant with lag and delay in physical units.
fit::PlantModel three_mode_model() {
  fit::PlantModel m;
  m.output = fit::OutputKind::kPosition;
  m.gain = 350.0;
  m.rigid_pole_rad_s = 4.0;
  m.modes = {{{2.0 * 140.0, 0.02}, {2.0 * 300.0, 0.05}},  // listed out of order on purpose
             {{2.0 * 40.0, 0.03}, {2.0 * 95.0, 0.04}},
             {{2.0 * 410.0, 0.01}, {2.0 * 520.0, 0.02}}};
  m.lag_pole_rad_s = 3000.0;
  m.delay_s = 2.5e-4;
  return m;
}

using test::expect_input_error;

TEST(Normalize, E24DemoPlantPrintedParameters) {
  // E24: Im = 1, Il = 8, b = 0.2, k = 8 ⇒ ωz = 1, ξz = 0.0125, ωn = 3, ξ = 0.0375 [V].
  const NormalizedPlant p = normalize(e24_model());
  EXPECT_DOUBLE_EQ(p.omega_z, 1.0);
  EXPECT_DOUBLE_EQ(p.motor_inertia, 1.0);
  EXPECT_DOUBLE_EQ(p.r, 3.0);
  EXPECT_DOUBLE_EQ(p.zeta_z, 0.0125);
  EXPECT_DOUBLE_EQ(p.zeta_p, 0.0375);
  EXPECT_EQ(p.a, 0.0);
  EXPECT_TRUE(p.higher_modes.empty());
  EXPECT_TRUE(p.hf.empty());
  EXPECT_TRUE(p.frictionless_consistent(1e-12));  // ξ = r·ξz exactly: the physical plant has no friction
  // Motor TF of the physical plant (C3.12): (Il s² + b s + k)/(s(Im Il s² + b(Im+Il)s + k(Im+Il))).
  const core::TransferFunction physical(Polynomial{8.0, 0.2, 8.0}, Polynomial{8.0, 1.8, 72.0, 0.0});
  const core::TransferFunction motor = p.motor();
  for (double w : core::log_space(0.01, 100.0, 41))
    EXPECT_LT(std::abs(motor.frequency_response(w) / physical.frequency_response(w) - 1.0), 1e-13) << w;
}

TEST(Normalize, FrictionlessLoadTransferFunctionMatchesPhysics) {
  // Catalog §0: Pl = (1/s)(2ξz s + 1)/(s² + 2ξz r² s + r²); for E24 ωl/Tm = (b s + k)/(s(Im Il s² + b J s + k J)).
  const NormalizedPlant p = normalize(e24_model());
  const std::optional<core::TransferFunction> load = p.load();
  ASSERT_TRUE(load.has_value());
  const core::TransferFunction physical(Polynomial{0.2, 8.0}, Polynomial{8.0, 1.8, 72.0, 0.0});
  for (double w : core::log_space(0.01, 100.0, 41))
    EXPECT_LT(std::abs(load->frequency_response(w) / physical.frequency_response(w) - 1.0), 1e-12) << w;
}

TEST(Normalize, MeasuredResponseReconstructsTheFittedModel) {
  // Independent: fit::PlantModel::response evaluates the model as fitted (lag 1/(s+p), delay, 1/s).
  HfDynamics extra;
  extra.current_lag_s = 1.0e-4;
  extra.feedback_filter_s = 2.0e-4;
  extra.delay_s = 1.0e-4;  // adds to the model's delay
  for (fit::OutputKind output : {fit::OutputKind::kPosition, fit::OutputKind::kVelocity}) {
    fit::PlantModel m = three_mode_model();
    m.output = output;
    const NormalizedPlant p = normalize(m, extra);
    EXPECT_EQ(p.output, output);
    EXPECT_DOUBLE_EQ(p.omega_z, 80.0);
    EXPECT_DOUBLE_EQ(p.r, 190.0 / 80.0);
    EXPECT_DOUBLE_EQ(p.a, 4.0 / 80.0);
    ASSERT_EQ(p.higher_modes.size(), 2u);
    EXPECT_DOUBLE_EQ(p.higher_modes[0].antiresonance.omega_rad_s, 280.0 / 80.0);  // sorted by resonance
    EXPECT_DOUBLE_EQ(p.higher_modes[1].resonance.omega_rad_s, 1040.0 / 80.0);
    // Im = 1/(K Π(ωzi/ωi)² g_lag), g_lag = 1/p.
    const double k_design = 350.0 * std::pow(280.0 / 600.0, 2) * std::pow(820.0 / 1040.0, 2) / 3000.0;
    EXPECT_LT(rel_diff(p.motor_inertia, 1.0 / k_design), 1e-15);
    ASSERT_TRUE(p.hf.delay_s && p.hf.lag_pole_rad_s && p.hf.current_lag_s && p.hf.feedback_filter_s);
    EXPECT_DOUBLE_EQ(*p.hf.delay_s, (2.5e-4 + 1.0e-4) * 80.0);
    EXPECT_DOUBLE_EQ(*p.hf.lag_pole_rad_s, 3000.0 / 80.0);
    EXPECT_DOUBLE_EQ(*p.hf.current_lag_s, 1.0e-4 * 80.0);
    // Physical = normalized / (Im ωz) for velocity, / (Im ωz²) for position.
    const double scale = p.motor_inertia * p.omega_z * (output == fit::OutputKind::kPosition ? p.omega_z : 1.0);
    for (double w : core::log_space(0.1, 5000.0, 61)) {
      const std::complex<double> expected = m.response(w) * extra.response(w);
      EXPECT_LT(std::abs(p.measured_response(w / p.omega_z) / scale / expected - 1.0), 1e-12) << w;
    }
  }
}

TEST(Normalize, DesignModelHasUnitHighFrequencyAsymptoteAndHigherModesUnitDcGain) {
  const NormalizedPlant p = normalize(three_mode_model());
  const core::TransferFunction design = p.motor(false), full = p.motor(true);
  // s·Pm(s) → 1 (the torque scale is the design model's HF inertia).
  const double w = 1e6;
  EXPECT_LT(std::abs(std::complex<double>(0.0, w) * design.frequency_response(w) - 1.0), 1e-5);
  // The higher-mode factors have unit DC gain: both models agree far below mode 2.
  for (double lo : {1e-3, 1e-2})  // the difference grows like (ω/ω_mode2)², ω_mode2 = 7.5 here
    EXPECT_LT(std::abs(full.frequency_response(lo) / design.frequency_response(lo) - 1.0), 1e-4) << lo;
  EXPECT_FALSE(p.load().has_value());  // higher modes: no two-mass realization
}

TEST(Normalize, HfDynamicsExactResponseAndTimeScaling) {
  HfDynamics h;
  h.current_lag_s = 0.002;
  h.feedback_filter_s = 0.001;
  h.delay_s = 0.0015;
  h.lag_pole_rad_s = 400.0;
  for (double w : {0.0, 1.0, 100.0, 2000.0}) {
    const std::complex<double> j(0.0, w);
    const std::complex<double> expected =
        std::exp(-j * 0.0015) * 400.0 / ((j * 0.002 + 1.0) * (j * 0.001 + 1.0) * (j + 400.0));
    EXPECT_LT(std::abs(h.response(w) - expected), 1e-15 * std::max(1.0, std::abs(expected)));
    EXPECT_NEAR(std::arg(h.actuator_response(w) / h.actuator_rational().frequency_response(w)), -w * 0.0015, 1e-12);
    EXPECT_LT(std::abs(h.feedback_response(w) - h.feedback_rational().frequency_response(w)), 1e-15);
    // The same dynamics on a time axis scaled by 50: H_n(ω/50) = H(ω).
    EXPECT_LT(std::abs(h.time_scaled(50.0).response(w / 50.0) - h.response(w)), 1e-14);
  }
  EXPECT_TRUE(HfDynamics{}.empty());
  EXPECT_FALSE(h.empty());
}

TEST(Normalize, FrictionlessConsistency) {
  EXPECT_FALSE(normalize(table51_model()).frictionless_consistent());  // a = 0.2, ξ = 0.15 vs r ξz = 0.18
  NormalizedPlant p = normalize(e24_model());
  p.zeta_p *= 1.01;
  EXPECT_TRUE(p.frictionless_consistent(0.05));
  EXPECT_FALSE(p.frictionless_consistent(0.005));
  p = normalize(e24_model());
  p.a = 0.04 * p.zeta_p * p.r;  // friction pole at 4 % of the modal decay rate
  EXPECT_TRUE(p.frictionless_consistent(0.05));
  EXPECT_FALSE(p.frictionless_consistent(0.03));
}

TEST(FrictionTwoMass, Table51NormalizedEFric) {
  const NormalizedPlant p = normalize(table51_model());
  EXPECT_DOUBLE_EQ(p.motor_inertia, 2.0);
  EXPECT_DOUBLE_EQ(p.a, 0.2);
  const std::optional<FrictionTwoMass> m = physical_parameters_with_friction(p);
  ASSERT_TRUE(m.has_value());
  // Plan §2 E-fric [R] (8 printed decimals).
  EXPECT_NEAR(m->load_inertia, 8.06307520, 5e-9);
  EXPECT_NEAR(m->stiffness, 8.06307520, 5e-9);
  EXPECT_NEAR(m->load_viscous, 0.89378451, 5e-9);
  EXPECT_NEAR(m->damping, 0.07378451, 5e-9);
  EXPECT_NEAR(m->motor_viscous, 0.90621549, 5e-9);
  // Fixture: scipy fsolve on the five C3.12 coefficient equations (not the quadratic).
  const nlohmann::json& f = reference().at("e_fric");
  EXPECT_LT(rel_diff(m->load_inertia, f.at("load_inertia").get<double>()), 1e-12);
  EXPECT_LT(rel_diff(m->damping, f.at("damping").get<double>()), 1e-12);
  EXPECT_LT(rel_diff(m->motor_viscous, f.at("motor_viscous").get<double>()), 1e-12);
  EXPECT_LT(rel_diff(m->load_viscous, f.at("load_viscous").get<double>()), 1e-12);
  // De-normalized (Im = 2, ωz = 1): the table-5.1 preset's realization (machine/flexible_presets.hpp).
  const PhysicalTwoMass phys = to_physical(*m, p);
  EXPECT_DOUBLE_EQ(phys.motor_inertia, 2.0);
  EXPECT_LT(rel_diff(phys.load_inertia, 16.12615039151721), 1e-13);
  EXPECT_LT(rel_diff(phys.stiffness, 16.12615039151721), 1e-13);
  EXPECT_LT(rel_diff(phys.damping, 0.1475690234910330), 1e-13);
  EXPECT_LT(rel_diff(phys.motor_viscous, 1.812430976508967), 1e-13);
  EXPECT_LT(rel_diff(phys.load_viscous, 1.787569023491033), 1e-13);
}

/// C3.12 with friction in physical units: ωm/Tm = (Il s² + (b+bl)s + k)/Q and ωl/Tm = (b s + k)/Q,
/// Q = [(Im s² + (bm+b)s + k)(Il s² + (bl+b)s + k) − (b s + k)²]/s.
struct PhysicalTfs {
  core::TransferFunction motor, load;
};
PhysicalTfs physical_tfs(const PhysicalTwoMass& m) {
  const Polynomial motor_side{m.motor_inertia, m.motor_viscous + m.damping, m.stiffness};
  const Polynomial load_side{m.load_inertia, m.load_viscous + m.damping, m.stiffness};
  const Polynomial coupling{m.damping, m.stiffness};
  const Polynomial q4 = motor_side * load_side - coupling * coupling;
  const std::span<const double> c = q4.coefficients();
  const Polynomial q(std::vector<double>(c.begin(), c.end() - 1));  // constant term is exactly 0
  return {{load_side, q}, {coupling, q}};
}

TEST(FrictionTwoMass, RealizationReproducesDesignAndLoadModels) {
  const NormalizedPlant p = normalize(table51_model());
  const PhysicalTwoMass phys = to_physical(*physical_parameters_with_friction(p), p);
  const PhysicalTfs tf = physical_tfs(phys);
  const std::optional<core::TransferFunction> load = p.load();
  ASSERT_TRUE(load.has_value());
  const double scale = p.motor_inertia * p.omega_z;
  for (double w : core::log_space(0.01, 100.0, 41)) {
    EXPECT_LT(std::abs(tf.motor.frequency_response(w) * scale / p.motor(false).frequency_response(w) - 1.0), 1e-12);
    EXPECT_LT(std::abs(tf.load.frequency_response(w) * scale / load->frequency_response(w) - 1.0), 1e-12);
  }
}

TEST(FrictionTwoMass, FrictionlessSpecialCase) {
  // Plan §1.1 check: a = 0, ξ = ξz r ⇒ f = r² − 1, bl = bm = 0 (and b = 2ξz(r² − 1), catalog §0).
  for (double r : {1.2, 2.0, 3.0, 7.5})
    for (double zz : {0.0, 0.005, 0.05, 0.3}) {
      const std::optional<FrictionTwoMass> m = physical_parameters_with_friction(normalized_two_mass(r, zz));
      ASSERT_TRUE(m.has_value()) << r << " " << zz;
      EXPECT_LT(rel_diff(m->load_inertia, r * r - 1.0), 1e-13);
      EXPECT_LT(rel_diff(m->damping, 2.0 * zz * (r * r - 1.0)), 1e-13);
      EXPECT_EQ(m->motor_viscous, 0.0);
      EXPECT_EQ(m->load_viscous, 0.0);
    }
}

TEST(FrictionTwoMass, RandomPhysicalPlantsRoundTrip) {
  // Physical parameters → motor TF → modal PlantModel (numpy-free: core::Polynomial::roots) →
  // normalize → realization → de-normalize must return the parameters: the realization is unique.
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    PhysicalTwoMass truth;
    truth.motor_inertia = 0.01 + 2.0 * u(rng);
    truth.load_inertia = truth.motor_inertia * (0.3 + 10.0 * u(rng));
    truth.stiffness = 50.0 + 5000.0 * u(rng);
    const double wz = std::sqrt(truth.stiffness / truth.load_inertia);
    truth.damping = 0.05 * u(rng) * truth.load_inertia * wz;
    truth.motor_viscous = 0.05 * u(rng) * truth.motor_inertia * wz;
    truth.load_viscous = 0.05 * u(rng) * truth.load_inertia * wz;
    const PhysicalTfs tf = physical_tfs(truth);
    fit::PlantModel m;
    m.gain = tf.motor.num().leading() / tf.motor.den().leading();
    for (const std::complex<double>& x : tf.motor.den().roots())
      if (x.imag() == 0.0) m.rigid_pole_rad_s = -x.real();
    const auto modal = [](const Polynomial& quadratic_or_cubic) {
      for (const std::complex<double>& x : quadratic_or_cubic.roots())
        if (x.imag() > 0.0) return fit::ModalPair{std::abs(x), -x.real() / std::abs(x)};
      return fit::ModalPair{};
    };
    m.modes = {{modal(tf.motor.num()), modal(tf.motor.den())}};
    const NormalizedPlant p = normalize(m);
    const std::optional<FrictionTwoMass> n = physical_parameters_with_friction(p);
    ASSERT_TRUE(n.has_value()) << trial;
    const PhysicalTwoMass back = to_physical(*n, p);
    const double db = truth.load_inertia * wz;  // scale of the damping-like parameters
    EXPECT_LT(rel_diff(back.motor_inertia, truth.motor_inertia), 1e-10) << trial;
    EXPECT_LT(rel_diff(back.load_inertia, truth.load_inertia), 1e-9) << trial;
    EXPECT_LT(rel_diff(back.stiffness, truth.stiffness), 1e-9) << trial;
    EXPECT_LT(std::abs(back.damping - truth.damping), 1e-9 * db) << trial;
    EXPECT_LT(std::abs(back.motor_viscous - truth.motor_viscous), 1e-9 * db) << trial;
    EXPECT_LT(std::abs(back.load_viscous - truth.load_viscous), 1e-9 * db) << trial;
  }
}

TEST(FrictionTwoMass, NoPassiveRealizationWhenFrictionWouldBeNegative) {
  // Integrator plant with ζp ≠ r ζz: bm + bl = a r² = 0 forces bm = −bl ≠ 0. The realization still
  // exists (exact for the motor, checked below) but is not passive.
  const NormalizedPlant integrating = normalized_two_mass(3.0, 0.01, 0.05);
  EXPECT_FALSE(physical_parameters_with_friction(integrating).has_value());
  const std::optional<FrictionTwoMass> m = two_mass_realization(integrating);
  ASSERT_TRUE(m.has_value());
  EXPECT_FALSE(m->passive());
  EXPECT_LT(std::abs(m->motor_viscous + m->load_viscous), 1e-12);
  EXPECT_TRUE(integrating.load().has_value());
  // Pole damping far below what the antiresonance damping implies: load friction with negative
  // motor friction (numpy on the closed form: b = 1.46789, bl = 1.88789, bm = −1.79789).
  const std::optional<FrictionTwoMass> heavy = two_mass_realization(normalized_two_mass(3.0, 0.2, 0.01, 0.01));
  ASSERT_TRUE(heavy.has_value());
  EXPECT_FALSE(physical_parameters_with_friction(normalized_two_mass(3.0, 0.2, 0.01, 0.01)).has_value());
  EXPECT_NEAR(heavy->damping, 1.46789, 1e-5);
  EXPECT_NEAR(heavy->motor_viscous, -1.79789, 1e-5);
  // A rigid pole fast against a lightly damped antiresonance: the shaft damping b would be negative
  // (numpy: b = −1.83526), a non-minimum-phase load; no two-mass reading at all.
  const NormalizedPlant fast_rigid = normalized_two_mass(3.0, 0.01, 0.03, 0.5);
  EXPECT_FALSE(two_mass_realization(fast_rigid).has_value());
  EXPECT_FALSE(fast_rigid.load().has_value());
}

TEST(FrictionTwoMass, TestBedFitsHaveAnExactRealizationWithNegativeMotorFriction) {
  // Catalog A6 configuration 2 (eq. 8.14): antiresonance 49.9 rad/s ζ 0.24, resonance 254 rad/s
  // ζ 0.02, rigid pole 0.15 rad/s. Expected values: the closed form of the realization evaluated
  // by hand in numpy (f = 26.4841, b = 6.18055, bl = 6.53182, bm = −6.45394, normalized), and the
  // motor and load responses of the equations of motion (physical_tfs) against the design model.
  const NormalizedPlant p = normalize(two_mass_model(454.5, fit::RigidKind::kRealPole, 0.15, {49.9, 0.24}, {254.0, 0.02}));
  const std::optional<FrictionTwoMass> m = two_mass_realization(p);
  ASSERT_TRUE(m.has_value());
  EXPECT_FALSE(m->passive());
  EXPECT_NEAR(m->load_inertia, 26.4841, 1e-4);
  EXPECT_NEAR(m->damping, 6.18055, 1e-5);
  EXPECT_NEAR(m->load_viscous, 6.53182, 1e-5);
  EXPECT_NEAR(m->motor_viscous, -6.45394, 1e-5);
  const PhysicalTfs tf = physical_tfs(to_physical(*m, p));
  const std::optional<core::TransferFunction> load = p.load();
  ASSERT_TRUE(load.has_value());
  const double scale = p.motor_inertia * p.omega_z;
  for (double w : core::log_space(0.01, 100.0, 41)) {
    const double physical = p.physical_frequency(w);
    EXPECT_LT(std::abs(tf.motor.frequency_response(physical) * scale / p.motor(false).frequency_response(w) - 1.0), 1e-10);
    EXPECT_LT(std::abs(tf.load.frequency_response(physical) * scale / load->frequency_response(w) - 1.0), 1e-10);
  }
}

TEST(Normalize, BadInputsNameTheProblem) {
  fit::PlantModel m = e24_model();
  m.modes.clear();
  expect_input_error([&] { (void)normalize(m); }, "modes", "not a flexible plant: use a rigid-body tuning");

  m = e24_model();
  m.modes[0].resonance.omega_rad_s = 1.04;
  expect_input_error([&] { (void)normalize(m); }, "modes", "antiresonance above resonance: non-collocated or mis-fitted");
  m.modes[0].resonance.omega_rad_s = 0.8;  // r < 1: non-collocated
  expect_input_error([&] { (void)normalize(m); }, "modes", "antiresonance above resonance");

  m = e24_model();
  m.modes[0].resonance.zeta = -0.01;
  expect_input_error([&] { (void)normalize(m); }, "modes[0].resonance.zeta",
                     "unstable fit: mode 1 resonance pole pair at s = 0.03 + 2.999849996j");
  m = e24_model();
  m.modes[0].antiresonance.zeta = -0.02;
  expect_input_error([&] { (void)normalize(m); }, "modes[0].antiresonance.zeta",
                     "non-minimum-phase fit: mode 1 antiresonance zero pair at s = 0.02 + 0.99979998j");
  m = table51_model();
  m.rigid_pole_rad_s = -0.5;
  expect_input_error([&] { (void)normalize(m); }, "rigid_pole_rad_s", "unstable fit: rigid-body pole at s = +0.5");
  m = table51_model();
  m.lag_pole_rad_s = -10.0;
  expect_input_error([&] { (void)normalize(m); }, "lag_pole_rad_s", "unstable fit: lag pole at s = 10");
  m = table51_model();
  m.gain = -0.5;
  expect_input_error([&] { (void)normalize(m); }, "gain", "expected a gain K > 0");
  m.gain = std::nan("");
  expect_input_error([&] { (void)normalize(m); }, "gain", "expected a gain K > 0");
  m = table51_model();
  m.modes[0].antiresonance.omega_rad_s = 0.0;
  expect_input_error([&] { (void)normalize(m); }, "modes[0].antiresonance.omega_rad_s", "expected a frequency");
  m = table51_model();
  m.output = static_cast<fit::OutputKind>(7);
  expect_input_error([&] { (void)normalize(m); }, "output", "expected a velocity or position output");
  m = table51_model();
  m.delay_s = -1e-3;
  expect_input_error([&] { (void)normalize(m); }, "delay_s", "expected a delay [s] >= 0");

  HfDynamics hf;
  hf.current_lag_s = 0.0;
  expect_input_error([&] { (void)normalize(table51_model(), hf); }, "hf.current_lag_s", "expected a time constant [s] > 0");
  hf = {};
  hf.feedback_filter_s = std::nan("");
  expect_input_error([&] { (void)normalize(table51_model(), hf); }, "hf.feedback_filter_s", "time constant");
  hf = {};
  hf.lag_pole_rad_s = 100.0;
  m = table51_model();
  m.lag_pole_rad_s = 200.0;
  expect_input_error([&] { (void)normalize(m, hf); }, "hf.lag_pole_rad_s", "already has a lag pole");

  expect_input_error([] { (void)normalized_two_mass(1.02, 0.01); }, "r", "antiresonance above resonance");
  expect_input_error([] { (void)normalized_two_mass(0.5, 0.01); }, "r", "expected a resonance ratio");
  expect_input_error([] { (void)normalized_two_mass(2.0, -0.01); }, "zeta_z", "expected a damping ratio >= 0");
  expect_input_error([] { (void)normalized_two_mass(2.0, 0.01, 0.02, -1.0); }, "a", "expected a rigid pole >= 0");
}

}  // namespace
}  // namespace servotwin::tuning
