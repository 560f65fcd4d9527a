// Linear behaviour of the flexible plants: closed forms of catalog C3.12 (two-mass transfer
// functions and parameters), scipy fixtures (tools/reference/flexible_plant_reference.py) for the
// chain modes and the exact zero-order-hold responses, and the printed numbers of E4, E14, E37.

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "flexible_plant_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/machine/flexible_presets.hpp"

namespace servotwin::machine {
namespace {

using cd = std::complex<double>;

using test::fixture;
using test::max_relative_error;
using test::vec;

PlantConfig chain_config(MassChain chain, double ts, double lag = 0.0) {
  PlantConfig c;
  c.model = std::move(chain);
  c.settings.ts = ts;
  c.settings.current_lag = lag;
  return c;
}

// ---- C3.12 closed forms --------------------------------------------------------------------

TEST(TwoMassClosedForm, CatalogE4Parameters) {
  // E4 [V]: Im = 1, Il = 8, b = 0.2, k = 8 => wz = 1, xz = 0.0125, wn = 3, xi = 0.0375, r = 3,
  // K1 = 1, K2 = 0.025.
  const auto p = two_mass_parameters(1.0, 8.0, 8.0, 0.2);
  EXPECT_NEAR(p.omega_z, 1.0, 1e-15);
  EXPECT_NEAR(p.zeta_z, 0.0125, 1e-15);
  EXPECT_NEAR(p.omega_n, 3.0, 1e-15);
  EXPECT_NEAR(p.zeta, 0.0375, 1e-15);
  EXPECT_NEAR(p.r, 3.0, 1e-15);
  EXPECT_NEAR(p.k1, 1.0, 1e-15);
  EXPECT_NEAR(p.k2, 0.025, 1e-15);
}

TEST(TwoMassClosedForm, FrictionlessTransferFunctionsMatchC312) {
  // wm/Tm = (K1/s)(s^2 + 2 xz wz s + wz^2)/(s^2 + 2 xi wn s + wn^2);
  // wl/Tm = (K2/s)(s + wz/(2 xz))/(s^2 + 2 xi wn s + wn^2) (C3.12), on a grid of frequencies.
  const double im = 0.004815, il = 0.005085, k = 563.9, b = 0.0677;
  const MassChain chain = two_mass(im, il, k, b);
  const auto p = two_mass_parameters(chain);
  const auto motor = mass_chain_transfer_function(chain, PlantOutput::MotorVelocity);
  const auto load = mass_chain_transfer_function(chain, PlantOutput::LoadVelocity);
  const auto motor_pos = mass_chain_transfer_function(chain, PlantOutput::MotorPosition);
  const auto load_pos = mass_chain_transfer_function(chain, PlantOutput::LoadPosition);
  EXPECT_EQ(motor.den().degree(), 3);  // s (s^2 + ...): the s/s pair is not left in
  for (double w : {1.0, 30.0, 2 * std::numbers::pi * 53.0, 2 * std::numbers::pi * 76.0, 2000.0}) {
    const cd s(0.0, w);
    const cd poles = s * s + 2.0 * p.zeta * p.omega_n * s + p.omega_n * p.omega_n;
    const cd pm = p.k1 / s * (s * s + 2.0 * p.zeta_z * p.omega_z * s + p.omega_z * p.omega_z) / poles;
    const cd pl = p.k2 / s * (s + p.omega_z / (2.0 * p.zeta_z)) / poles;
    EXPECT_LT(std::abs(motor.frequency_response(w) - pm), 1e-12 * std::abs(pm)) << w;
    EXPECT_LT(std::abs(load.frequency_response(w) - pl), 1e-12 * std::abs(pl)) << w;
    EXPECT_LT(std::abs(motor_pos.frequency_response(w) - pm / s), 1e-12 * std::abs(pm / s)) << w;
    EXPECT_LT(std::abs(load_pos.frequency_response(w) - pl / s), 1e-12 * std::abs(pl / s)) << w;
  }
}

TEST(TwoMassClosedForm, ViscousFrictionPolynomialsMatchC312) {
  // With motor and load viscous friction (C3.12): wm/Tm = (Il s^2 + (b + bl) s + k)/(a3 s^3 +
  // a2 s^2 + a1 s + a0), wl/Tm = (b s + k)/(same), a3 = Il Im, a2 = Il (b + bm) + Im (b + bl),
  // a1 = bm (bl + b) + k (Im + Il) + bl b, a0 = k (bl + bm).
  const double im = 2.0, il = 16.0, k = 16.5, b = 0.15, bm = 1.8, bl = 1.7;
  const auto motor = mass_chain_transfer_function(two_mass(im, il, k, b, bm, bl), PlantOutput::MotorVelocity);
  const auto load = mass_chain_transfer_function(two_mass(im, il, k, b, bm, bl), PlantOutput::LoadVelocity);
  const double a3 = il * im, a2 = il * (b + bm) + im * (b + bl), a1 = bm * (bl + b) + k * (im + il) + bl * b,
               a0 = k * (bl + bm);
  const std::vector<double> den{1.0, a2 / a3, a1 / a3, a0 / a3};
  const std::vector<double> num_m{il / a3, (b + bl) / a3, k / a3};
  const std::vector<double> num_l{b / a3, k / a3};
  ASSERT_EQ(motor.den().degree(), 3);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(motor.den().coefficients()[static_cast<std::size_t>(i)], den[static_cast<std::size_t>(i)],
                1e-13 * std::abs(den[static_cast<std::size_t>(i)]));
    EXPECT_NEAR(load.den().coefficients()[static_cast<std::size_t>(i)], den[static_cast<std::size_t>(i)],
                1e-13 * std::abs(den[static_cast<std::size_t>(i)]));
  }
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(motor.num().coefficients()[i], num_m[i], 1e-13 * num_m[i]);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_NEAR(load.num().coefficients()[i], num_l[i], 1e-13 * num_l[i]);
}

TEST(TwoMassClosedForm, TransferFunctionInvariantUnderUnitChange) {
  // Scaling all inertias, stiffnesses and dampings by c scales the TF by 1/c exactly.
  const auto a = mass_chain_transfer_function(two_mass(0.5, 1.5, 40.0, 0.3, 0.1, 0.2), PlantOutput::LoadVelocity);
  const double c = 1e-6;
  const auto b = mass_chain_transfer_function(two_mass(0.5 * c, 1.5 * c, 40.0 * c, 0.3 * c, 0.1 * c, 0.2 * c),
                                              PlantOutput::LoadVelocity);
  for (double w : {0.1, 5.0, 9.0, 100.0})
    EXPECT_LT(std::abs(b.frequency_response(w) * c - a.frequency_response(w)), 1e-12 * std::abs(a.frequency_response(w)));
}

// ---- C3.13 modes ---------------------------------------------------------------------------

TEST(ChainModes, MatchScipyGeneralizedEigenproblemAndRayleighDamping) {
  const auto& f = fixture()["modes"];
  MassChain chain;
  chain.inertia = vec(f["inertia"]);
  chain.stiffness = vec(f["stiffness"]);
  chain.damping = vec(f["shaft_damping"]);
  chain.viscous = vec(f["viscous"]);
  const auto modes = chain_modes(chain);
  const auto omega = vec(f["omega"]);
  const auto zeta = vec(f["zeta"]);
  const double alpha = f["alpha"], beta = f["beta"];
  ASSERT_EQ(modes.size(), omega.size());
  EXPECT_EQ(modes[0].omega, 0.0);  // rigid-body mode of the free chain
  for (std::size_t i = 1; i < modes.size(); ++i) {
    EXPECT_NEAR(modes[i].omega, omega[i], 1e-12 * omega[i]) << i;
    EXPECT_NEAR(modes[i].zeta, zeta[i], 1e-12) << i;
    // Rayleigh closed form: zeta_i = alpha / (2 w_i) + beta w_i / 2 (C3.13).
    EXPECT_NEAR(modes[i].zeta, alpha / (2.0 * omega[i]) + beta * omega[i] / 2.0, 1e-12) << i;
  }
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const auto shape = vec(f["shapes"][i]);
    for (std::size_t j = 0; j < shape.size(); ++j)
      EXPECT_NEAR(modes[i].shape(static_cast<Eigen::Index>(j)), shape[j], 1e-10) << i << "," << j;
  }
}

TEST(ChainModes, TwoMassModeIsC312Resonance) {
  // C3.13 two-mass example: w2 = sqrt(k (M1 + M2)/(M1 M2)); E4 modal M1 = 1, M2 = 8:
  // phi11 = 1/3, phi12 = -0.9428 (catalog prints phi12 on the motor, first entry of mode 2).
  const auto modes = chain_modes(two_mass(1.0, 8.0, 8.0, 0.0));
  ASSERT_EQ(modes.size(), 2U);
  EXPECT_NEAR(modes[1].omega, 3.0, 1e-14);
  EXPECT_NEAR(modes[0].shape(0), 1.0 / 3.0, 1e-14);
  EXPECT_NEAR(std::abs(modes[1].shape(0)), 0.9428090415820634, 1e-13);
}

// ---- exact ZOH sampling --------------------------------------------------------------------

void expect_zoh_case(const nlohmann::json& f, double tolerance) {
  MassChain chain;
  chain.inertia = vec(f["inertia"]);
  chain.stiffness = vec(f["stiffness"]);
  chain.damping = vec(f["damping"]);
  chain.viscous = vec(f["viscous"]);
  FlexiblePlant plant(chain_config(chain, f["ts"], f["current_lag"]));
  ASSERT_TRUE(plant.is_linear());
  const auto u = vec(f["u"]);
  std::vector<double> mp, mv, lp, lv;
  for (double uk : u) {
    const auto m = plant.step(uk);
    mp.push_back(m.motor_position), mv.push_back(m.motor_velocity);
    lp.push_back(m.load_position), lv.push_back(m.load_velocity);
    EXPECT_EQ(m.y, m.motor_velocity);  // default output, no noise, no quantization
  }
  EXPECT_LT(max_relative_error(mp, vec(f["motor_position"])), tolerance);
  EXPECT_LT(max_relative_error(mv, vec(f["motor_velocity"])), tolerance);
  EXPECT_LT(max_relative_error(lp, vec(f["load_position"])), tolerance);
  EXPECT_LT(max_relative_error(lv, vec(f["load_velocity"])), tolerance);
}

TEST(FlexiblePlantZoh, TwoMassMatchesScipyDlsim) { expect_zoh_case(fixture()["zoh_two_mass"], 1e-10); }
TEST(FlexiblePlantZoh, ThreeMassChainWithCurrentLagMatchesScipyDlsim) {
  expect_zoh_case(fixture()["zoh_chain_lag"], 1e-10);
}
TEST(FlexiblePlantZoh, RigidMassMatchesScipyDlsim) { expect_zoh_case(fixture()["zoh_rigid"], 1e-12); }

TEST(FlexiblePlantZoh, CommandIsHeldOverThePeriod) {
  // A rigid mass under a torque T held for one period: w = T ts / J, phi = T ts^2 / (2 J)
  // exactly; with no command afterwards the mass coasts at that velocity.
  MassChain rigid;
  rigid.inertia = {0.25};
  FlexiblePlant plant(chain_config(rigid, 0.002));
  const auto m = plant.step(3.0);
  EXPECT_NEAR(m.motor_velocity, 3.0 * 0.002 / 0.25, 1e-15);
  EXPECT_NEAR(m.motor_position, 3.0 * 0.002 * 0.002 / (2 * 0.25), 1e-17);
  const auto m2 = plant.step(0.0);
  EXPECT_NEAR(m2.motor_velocity, m.motor_velocity, 1e-15);
  EXPECT_NEAR(m2.motor_position, 3.0 * m.motor_position, 1e-17);  // phi + w ts = phi + 2 phi
}

TEST(FlexiblePlantZoh, DelayShiftsTheCommandByWholeSamples) {
  const MassChain chain = two_mass(1.0, 2.0, 50.0, 0.5, 0.1, 0.1);
  PlantConfig config = chain_config(chain, 0.01);
  FlexiblePlant direct(config);
  config.settings.delay_samples = 3;
  FlexiblePlant delayed(config);
  std::vector<double> a, b;
  for (int k = 0; k < 50; ++k) {
    const double u = std::sin(0.3 * k) + 0.2;
    b.push_back(delayed.step(u).load_position);
    if (k < 3) {
      EXPECT_EQ(b.back(), 0.0);
    }
    a.push_back(direct.step(u).load_position);
  }
  for (std::size_t k = 3; k < b.size(); ++k) EXPECT_EQ(b[k], a[k - 3]) << k;
}

// ---- transfer-function plants --------------------------------------------------------------

void expect_tf_case(const nlohmann::json& f) {
  PlantConfig c;  // the fixture's expanded num/den; its response comes from the printed factors
  c.model = TransferFunctionModel{core::TransferFunction(core::Polynomial(vec(f["num"])), core::Polynomial(vec(f["den"])))};
  c.settings.ts = f["ts"];
  FlexiblePlant plant(c);
  const auto u = vec(f["u"]);
  std::vector<double> y;
  for (double uk : u) y.push_back(plant.step(uk).y);
  EXPECT_LT(max_relative_error(y, vec(f["y"])), 1e-9);
}

TEST(TransferFunctionPlant, RfidDemoMatchesScipyDlsim) { expect_tf_case(fixture()["tf_rfid_demo"]); }

TEST(TransferFunctionPlant, CurrentLagEqualsSeriesFirstOrderFactor) {
  // Fixture: testbed-2 times 1/(1e-3 s + 1) discretized by scipy; the plant gets the undelayed TF
  // and current_lag = 1e-3.
  const auto& f = fixture()["tf_testbed2_lag"];
  PlantConfig c = flexible_preset("testbed-2");
  c.settings.current_lag = 1e-3;
  ASSERT_EQ(c.settings.ts, f["ts"].get<double>());
  FlexiblePlant plant(c);
  std::vector<double> y;
  for (double uk : vec(f["u"])) y.push_back(plant.step(uk).y);
  EXPECT_LT(max_relative_error(y, vec(f["y"])), 1e-9);
  // And its transfer function is the series product.
  const auto tf = plant.transfer_function();
  const core::TransferFunction want(core::Polynomial(vec(f["num"])), core::Polynomial(vec(f["den"])));
  for (double w : {1.0, 50.0, 254.0, 1000.0})
    EXPECT_LT(std::abs(tf.frequency_response(w) - want.frequency_response(w)), 1e-12 * std::abs(want.frequency_response(w)));
}

TEST(TransferFunctionPlant, ReportsNoPhysicalStates) {
  FlexiblePlant plant(flexible_preset("rfid-demo"));
  const auto m = plant.step(1.0);
  EXPECT_TRUE(std::isnan(m.motor_position));
  EXPECT_EQ(m.y, m.y_exact);
  EXPECT_THROW((void)plant.shaft_torque(0), core::InputError);
  EXPECT_THROW((void)plant.transfer_function(PlantOutput::LoadVelocity), core::InputError);
}

TEST(TransferFunctionPlant, RejectsUnstableOrImproperModels) {
  PlantConfig c;
  c.settings.ts = 0.01;
  c.model = TransferFunctionModel{core::TransferFunction(core::Polynomial{1.0}, core::Polynomial{1.0, -0.5})};
  try {
    validate(c);
    FAIL() << "unstable plant accepted";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "den");
  }
  c.model = TransferFunctionModel{core::TransferFunction(core::Polynomial{1.0, 0.0, 1.0}, core::Polynomial{1.0, 1.0})};
  EXPECT_THROW(validate(c), core::InputError);
  // A position output with an integrator is marginal and allowed.
  c.model = TransferFunctionModel{core::TransferFunction(core::Polynomial{1.0}, core::Polynomial{1.0, 2.0, 0.0})};
  EXPECT_NO_THROW(validate(c));
}

// ---- presets -------------------------------------------------------------------------------

TEST(FlexiblePresets, TransferFunctionsMatchNumpyProductsOfPrintedFactors) {
  for (const std::string name : {"testbed-1", "testbed-2", "rfid-demo", "gantry-crane", "table-5.1"}) {
    const auto& f = fixture()["presets"][name];
    const FlexiblePlant plant(flexible_preset(name));
    const auto tf = plant.transfer_function();
    const core::TransferFunction want(core::Polynomial(vec(f["num"])), core::Polynomial(vec(f["den"])));
    for (double w : {0.05, 0.5, 1.0, 3.0, 35.0, 70.8, 260.0, 2000.0}) {
      const cd a = tf.frequency_response(w), b = want.frequency_response(w);
      EXPECT_LT(std::abs(a - b), 1e-11 * std::abs(b)) << name << " at " << w;
    }
  }
}

TEST(FlexiblePresets, RfidDemoModesAreTheCatalogValues) {
  // E14 [V]: modes 0.9992 / 0.0227 and 3.0199 / 0.1631; zeros 0.2461 (0.129), 1.4367 (0.0393).
  const auto tf = FlexiblePlant(flexible_preset("rfid-demo")).transfer_function();
  std::vector<core::ModalInfo> poles, zeros;
  for (auto p : tf.poles())
    if (p.imag() > 0) poles.push_back(core::modal_info(p));
  for (auto z : tf.zeros())
    if (z.imag() > 0) zeros.push_back(core::modal_info(z));
  ASSERT_EQ(poles.size(), 2U);
  ASSERT_EQ(zeros.size(), 2U);
  EXPECT_NEAR(poles[0].omega_rad_s, 0.9992, 5e-5);
  EXPECT_NEAR(poles[0].zeta, 0.0227, 5e-5);
  EXPECT_NEAR(poles[1].omega_rad_s, 3.0199, 5e-5);
  EXPECT_NEAR(poles[1].zeta, 0.1631, 5e-5);
  EXPECT_NEAR(zeros[0].omega_rad_s, 0.2461, 5e-5);
  EXPECT_NEAR(zeros[0].zeta, 0.129, 5e-4);
  EXPECT_NEAR(zeros[1].omega_rad_s, 1.4367, 5e-5);
  EXPECT_NEAR(zeros[1].zeta, 0.0393, 5e-5);
}

TEST(FlexiblePresets, TestBedResonanceRatiosAreE37) {
  // E37 [V]: r1 = w1/wz1 = 2.006 (configuration 1), r = 5.09 (configuration 2).
  for (const auto& [name, r] : {std::pair<std::string, double>{"testbed-1", 2.006}, {"testbed-2", 5.09}}) {
    const auto tf = FlexiblePlant(flexible_preset(name)).transfer_function();
    double pole = 1e300, zero = 1e300;
    for (auto p : tf.poles())
      if (p.imag() > 0) pole = std::min(pole, std::abs(p));
    for (auto z : tf.zeros())
      if (z.imag() > 0) zero = std::min(zero, std::abs(z));
    EXPECT_NEAR(pole / zero, r, 5e-4) << name;
  }
}

TEST(FlexiblePresets, GantryCraneModeAndRopeLength) {
  // A1/E35: wn = 4.22 rad/s, xi = 0.0079; rope l = g/wn^2 = 0.551 m, K = -1/l.
  const auto tf = FlexiblePlant(flexible_preset("gantry-crane")).transfer_function();
  const auto p = core::modal_info(tf.poles()[0]);
  EXPECT_NEAR(p.omega_rad_s, 4.22, 1e-12);
  EXPECT_NEAR(p.zeta, 0.0079, 1e-12);
  EXPECT_NEAR(-1.0 / tf.num().coefficients()[0], 0.551, 5e-4);
}

TEST(FlexiblePresets, Table51PhysicalRealizationHasTheFittedParameters) {
  // E10 true values: K = 0.5, a = 0.2, wn = 3, xn = 0.15, wz = 1, xz = 0.06.
  const auto tf = FlexiblePlant(flexible_preset("table-5.1")).transfer_function();
  EXPECT_NEAR(tf.num().coefficients()[0], 0.5, 1e-12);
  std::vector<double> real_poles;
  core::ModalInfo mode;
  for (auto p : tf.poles()) {
    if (p.imag() > 0) mode = core::modal_info(p);
    if (p.imag() == 0) real_poles.push_back(p.real());
  }
  ASSERT_EQ(real_poles.size(), 1U);
  EXPECT_NEAR(real_poles[0], -0.2, 1e-12);
  EXPECT_NEAR(mode.omega_rad_s, 3.0, 1e-12);
  EXPECT_NEAR(mode.zeta, 0.15, 1e-12);
  const auto z = core::modal_info(tf.zeros()[0]);
  EXPECT_NEAR(z.omega_rad_s, 1.0, 1e-12);
  EXPECT_NEAR(z.zeta, 0.06, 1e-12);
}

TEST(FlexiblePresets, MotorBenchFrequenciesAndInertia) {
  const auto config = flexible_preset("motor-bench");
  const auto& chain = std::get<MassChain>(config.model);
  const auto p = two_mass_parameters(chain);
  EXPECT_NEAR(p.omega_z / (2 * std::numbers::pi), 53.0, 1e-9);
  EXPECT_NEAR(p.omega_n / (2 * std::numbers::pi), 76.0, 1e-9);
  EXPECT_NEAR(chain.inertia[0] + chain.inertia[1], 0.0099, 1e-15);
  EXPECT_NEAR(p.zeta_z, 0.02, 1e-12);
  const FlexiblePlant plant(config);
  EXPECT_FALSE(plant.is_linear());
}

TEST(FlexiblePresets, UnknownNameListsKnownOnes) {
  try {
    (void)flexible_preset("testbed-3");
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("motor-bench"), std::string::npos);
  }
  EXPECT_EQ(flexible_preset_names().size(), 7U);
  for (const auto& name : flexible_preset_names()) EXPECT_EQ(flexible_preset(name).name, name);
}

// ---- validation ----------------------------------------------------------------------------

TEST(FlexiblePlantValidation, NamesTheBadField) {
  const auto field_of = [](const PlantConfig& c) {
    try {
      validate(c);
    } catch (const core::InputError& e) {
      return e.where().field;
    }
    return std::string("<accepted>");
  };
  PlantConfig c = chain_config(two_mass(1.0, 2.0, 10.0, 0.1), 0.01);
  EXPECT_EQ(field_of(c), "<accepted>");
  auto bad = c;
  std::get<MassChain>(bad.model).inertia[1] = 0.0;
  EXPECT_EQ(field_of(bad), "inertia[1]");
  bad = c;
  std::get<MassChain>(bad.model).stiffness[0] = std::nan("");
  EXPECT_EQ(field_of(bad), "stiffness[0]");
  bad = c;
  std::get<MassChain>(bad.model).damping[0] = -1.0;
  EXPECT_EQ(field_of(bad), "damping[0]");
  bad = c;
  std::get<MassChain>(bad.model).friction = {KarnoppFriction{}, KarnoppFriction{1.0, 0.5, 0.0}};
  EXPECT_EQ(field_of(bad), "friction[1].stiction");
  bad = c;
  bad.settings.ts = 0.0;
  EXPECT_EQ(field_of(bad), "ts");
  bad = c;
  bad.settings.noise_std = -0.1;
  EXPECT_EQ(field_of(bad), "noise_std");
  bad = c;
  bad.settings.delay_samples = -1;
  EXPECT_EQ(field_of(bad), "delay_samples");
  bad = c;
  std::get<MassChain>(bad.model).stiffness = {};
  EXPECT_EQ(field_of(bad), "stiffness");
  EXPECT_THROW(FlexiblePlant{bad}, core::InputError);
}

}  // namespace
}  // namespace servotwin::machine
