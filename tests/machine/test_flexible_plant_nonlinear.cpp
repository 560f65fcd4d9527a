// Nonlinear elements and the sensor chain of the flexible plants: Karnopp friction (catalog C5.10),
// the backlash dead zone (C5.10, describing function E11), the sliding/gap regimes that the
// integrator must solve exactly, and seeded noise / quantization. Fixture values come from
// tools/reference/flexible_plant_reference.py (scipy), the rest from closed forms cited per test.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "flexible_plant_test_support.hpp"
#include "servotwin/machine/flexible_plant.hpp"
#include "servotwin/machine/flexible_presets.hpp"

namespace servotwin::machine {
namespace {

using test::fixture;
using test::max_relative_error;
using test::vec;

PlantConfig config_of(MassChain chain, double ts) {
  PlantConfig c;
  c.model = std::move(chain);
  c.settings.ts = ts;
  return c;
}

MassChain rigid_with_friction(double inertia, KarnoppFriction friction) {
  MassChain c;
  c.inertia = {inertia};
  c.friction = {friction};
  return c;
}

// ---- Karnopp friction ----------------------------------------------------------------------

TEST(Karnopp, TorqueBelowStictionNeverMoves) {
  // C5.10: |Te| < TS at rest -> stick, velocity exactly 0.
  FlexiblePlant plant(config_of(rigid_with_friction(0.5, {1.0, 2.0, 0.01}), 0.001));
  for (int k = 0; k < 2000; ++k) {
    const double torque = 1.99 * std::sin(0.01 * k);
    const auto m = plant.step(torque);
    ASSERT_EQ(m.motor_velocity, 0.0) << k;
    ASSERT_EQ(m.motor_position, 0.0) << k;
  }
  EXPECT_EQ(plant.stuck_mask(), 1U);
}

TEST(Karnopp, TorqueAboveStictionBreaksAway) {
  // Breakaway at T = 2.1 > TS = 2: inside the band |w| <= dv the friction is TS, so
  // w' = (T - TS)/J until w = dv at t_b = dv J/(T - TS), then w' = (T - TC)/J (C5.10).
  const double j = 0.5, ts = 0.001, t = 2.1, tc = 1.0, tstat = 2.0, dv = 0.01;
  FlexiblePlant plant(config_of(rigid_with_friction(j, {tc, tstat, dv}), ts));
  const double tb = dv * j / (t - tstat);
  const double h = ts / plant.substeps();
  for (int k = 1; k <= 300; ++k) {
    const auto m = plant.step(t);
    const double time = k * ts;
    const double expected = time < tb ? (t - tstat) / j * time : dv + (t - tc) / j * (time - tb);
    // Only the switch from breakaway to sliding is resolved to one sub-step h.
    EXPECT_NEAR(m.motor_velocity, expected, (t - tc) / j * h + 1e-12) << k;
    EXPECT_GT(m.motor_velocity, 0.0);
  }
  EXPECT_EQ(plant.stuck_mask(), 0U);
}

TEST(Karnopp, LoadStaysExactlyStillUntilShaftTorqueReachesStiction) {
  // Table 5.1 plant with E12's load friction TS = 3 (preset): a slow ramp of motor torque twists
  // the shaft quasi-statically, so the load's external torque is ~ the motor torque; the load
  // must not move at all below TS and must break away just above it.
  const PlantConfig config = flexible_preset("table-5.1");
  FlexiblePlant plant(config);
  const double ts = config.settings.ts, rate = 0.05;  // N m/s
  bool moved = false;
  for (int k = 0; k < 8000; ++k) {
    const double torque = rate * k * ts;
    const auto m = plant.step(torque);
    if (torque < 2.9) {
      ASSERT_EQ(m.load_velocity, 0.0) << k;
      ASSERT_EQ(m.load_position, 0.0) << k;
    }
    if (m.load_velocity > 0.0) {
      moved = true;
      EXPECT_GT(torque, 2.9);
      EXPECT_LT(torque, 3.2);
      break;
    }
  }
  EXPECT_TRUE(moved);
}

TEST(Karnopp, StopsWithoutChatter) {
  // A sliding mass with zero command decelerates at TC/J, stops at t = w0 J/TC and then stays
  // exactly at rest (no sign flips), for a stick band and for a pure Coulomb stop (dv = 0).
  for (double dv : {0.0, 0.05}) {
    const double j = 0.2, tc = 0.4, w0 = 3.0, ts = 0.001;
    FlexiblePlant plant(config_of(rigid_with_friction(j, {tc, 0.6, dv}), ts));
    plant.set_chain_state(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, w0));
    const double stop = w0 * j / tc;  // 1.5 s
    const double h = ts / plant.substeps();
    for (int k = 1; k <= 3000; ++k) {
      const auto m = plant.step(0.0);
      const double time = k * ts;
      if (time > stop + 2 * h + dv * j / tc) {
        ASSERT_EQ(m.motor_velocity, 0.0) << "dv " << dv << " k " << k;
      } else {
        ASSERT_GE(m.motor_velocity, 0.0);
        EXPECT_NEAR(m.motor_velocity, std::max(0.0, w0 - tc / j * time), tc / j * h + dv + 1e-12);
      }
    }
    // The stopping distance w0^2 J / (2 TC) up to the last sub-step before the band.
    EXPECT_NEAR(plant.measure().motor_position, w0 * w0 * j / (2 * tc), w0 * h + dv * stop);
  }
}

TEST(Karnopp, SlidingFrictionIsIntegratedExactly) {
  // While the load slides in one direction its Coulomb torque is constant: the fixture solves
  // that linear problem with the friction as a constant input (scipy ZOH), so the plant must
  // agree to rounding, whatever the sub-step count.
  const auto& f = fixture()["coulomb_slide"];
  MassChain chain;
  chain.inertia = vec(f["inertia"]);
  chain.stiffness = vec(f["stiffness"]);
  chain.damping = vec(f["damping"]);
  const double tc = f["coulomb"];
  chain.friction = {KarnoppFriction{}, KarnoppFriction{tc, tc, 0.0}};
  FlexiblePlant plant(config_of(chain, f["ts"]));
  const double w0 = f["initial_velocity"];
  plant.set_chain_state(Eigen::VectorXd::Zero(2), Eigen::VectorXd::Constant(2, w0));
  std::vector<double> mv, lp, lv;
  for (std::size_t k = 0; k < vec(f["load_velocity"]).size(); ++k) {
    const auto m = plant.step(f["torque"].get<double>());
    mv.push_back(m.motor_velocity), lp.push_back(m.load_position), lv.push_back(m.load_velocity);
  }
  EXPECT_LT(max_relative_error(mv, vec(f["motor_velocity"])), 1e-11);
  EXPECT_LT(max_relative_error(lp, vec(f["load_position"])), 1e-11);
  EXPECT_LT(max_relative_error(lv, vec(f["load_velocity"])), 1e-11);
}

// ---- backlash ------------------------------------------------------------------------------

// First Fourier harmonic of the shaft torque for a twist A sin(theta), via the plant's own torque
// evaluation (set_chain_state + shaft_torque), divided by A: the describing function (C5.10).
double measured_describing_function(double amplitude, double k, double gap) {
  MassChain chain = two_mass(1.0, 1.0, k, 0.0);
  chain.backlash = {gap};
  FlexiblePlant plant(config_of(chain, 0.001));
  const int n = 20000;
  double b1 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double theta = 2.0 * std::numbers::pi * (i + 0.5) / n;
    Eigen::VectorXd angles(2);
    angles << amplitude * std::sin(theta), 0.0;
    plant.set_chain_state(angles, Eigen::VectorXd::Zero(2));
    b1 += plant.shaft_torque(0) * std::sin(theta);
  }
  return 2.0 * b1 / n / amplitude;
}

TEST(Backlash, DescribingFunctionMatchesE11) {
  // E11 [D]: N(A = D) = 0.39100 Kk, N(5D) = 0.87289 Kk, N(A <= D/2) = 0, N -> Kk.
  const double k = 250.0, gap = 0.004;
  EXPECT_NEAR(measured_describing_function(gap, k, gap) / k, 0.39100, 5e-5);
  EXPECT_NEAR(measured_describing_function(5 * gap, k, gap) / k, 0.87289, 5e-5);
  EXPECT_EQ(measured_describing_function(0.5 * gap, k, gap), 0.0);
  EXPECT_EQ(measured_describing_function(0.2 * gap, k, gap), 0.0);
  EXPECT_NEAR(measured_describing_function(1000 * gap, k, gap) / k, 1.0, 2e-3);
  // And the closed form of C5.10 (with the gamma = asin(D/(2A)) fix, defect 8) in between.
  for (double a : {0.6 * gap, 0.8 * gap, 2 * gap, 3.3 * gap}) {
    const double r = gap / (2 * a), gamma = std::asin(r);
    const double closed = 2.0 / std::numbers::pi * (std::numbers::pi / 2 - gamma - r * std::sqrt(1 - r * r));
    EXPECT_NEAR(measured_describing_function(a, k, gap) / k, closed, 5e-5) << a / gap;
  }
}

TEST(Backlash, OpenGapLeavesLoadExactlyStill) {
  // In the gap no torque is transmitted: the motor is a free mass (phi = T t^2 / (2 Im) exactly)
  // and the load does not move at all until the twist reaches D/2.
  const double im = 0.01, gap = 0.02, torque = 0.05, ts = 0.001;
  MassChain chain = two_mass(im, 0.03, 300.0, 0.1);
  chain.backlash = {gap};
  FlexiblePlant plant(config_of(chain, ts));
  int in_gap = 0;
  for (int k = 1; k < 200; ++k) {
    const auto m = plant.step(torque);
    const double free = torque * (k * ts) * (k * ts) / (2 * im);
    if (free + torque * ts * ts / im < gap / 2) {  // the whole next sub-step stays inside the gap
      ++in_gap;
      ASSERT_EQ(m.load_position, 0.0) << k;
      ASSERT_EQ(m.load_velocity, 0.0) << k;
      EXPECT_NEAR(m.motor_position, free, 1e-14) << k;
    }
  }
  EXPECT_GT(in_gap, 20);
  EXPECT_GT(plant.measure().load_position, 0.0);  // contact made later
}

TEST(Backlash, SinusoidalDriveMatchesScipySolveIvp) {
  // Fixture: solve_ivp (DOP853, rtol 1e-11) on the discontinuous dead-zone dynamics with the
  // command held per sample. The plant's only error is the timing of contact changes (one
  // sub-step): small with the automatic sub-steps, and shrinking as sub-steps are refined.
  const auto& f = fixture()["backlash_sine"];
  const auto& p = f["params"];
  MassChain chain = two_mass(p["im"], p["il"], p["k"], p["b"], p["bm"], p["bl"]);
  chain.backlash = {p["D"].get<double>()};
  const auto run = [&](int substeps) {
    PlantConfig c = config_of(chain, f["ts"]);
    c.settings.substeps = substeps;
    FlexiblePlant plant(c);
    std::vector<double> lp;
    for (double u : vec(f["u"])) lp.push_back(plant.step(u).load_position);
    return max_relative_error(lp, vec(f["load_position"]));
  };
  const double automatic = run(0);
  const double fine = run(512);
  EXPECT_LT(automatic, 1e-3);  // measured 3.1e-4 with 8 sub-steps
  EXPECT_LT(fine, 1e-5);       // measured 1.4e-6 with 512
  EXPECT_LT(fine, automatic / 8);
}

// ---- sensor chain --------------------------------------------------------------------------

TEST(PlantSensor, NoiseIsSeededAndHasTheRequestedStd) {
  PlantConfig c = config_of(two_mass(1.0, 2.0, 40.0, 0.2, 0.5, 0.5), 0.001);
  c.settings.noise_std = 0.25;
  c.settings.seed = 42;
  FlexiblePlant a(c), b(c);
  c.settings.seed = 43;
  FlexiblePlant other(c);
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  bool differs = false;
  for (int k = 0; k < n; ++k) {
    const double u = std::sin(0.001 * k);
    const auto ma = a.step(u), mb = b.step(u), mo = other.step(u);
    ASSERT_EQ(ma.y, mb.y);
    EXPECT_EQ(ma.y_exact, mo.y_exact);
    differs = differs || ma.y != mo.y;
    const double e = ma.y - ma.y_exact;
    sum += e, sum2 += e * e;
  }
  EXPECT_TRUE(differs);
  const double mean = sum / n, std_dev = std::sqrt(sum2 / n - mean * mean);
  // Sampling error of the std ~ 0.25/sqrt(2n) = 4e-4; of the mean 0.25/sqrt(n) = 5.6e-4.
  EXPECT_NEAR(std_dev, 0.25, 0.005);
  EXPECT_NEAR(mean, 0.0, 0.003);
  // reset() restarts the stream.
  a.reset();
  FlexiblePlant fresh(config_of(two_mass(1.0, 2.0, 40.0, 0.2, 0.5, 0.5), 0.001));
  c.settings.seed = 42;
  FlexiblePlant again(c);
  EXPECT_EQ(a.step(0.3).y, again.step(0.3).y);
}

TEST(PlantSensor, QuantizationRoundsToTheStep) {
  PlantConfig c = config_of(two_mass(1.0, 2.0, 40.0, 0.2, 0.5, 0.5), 0.001);
  c.settings.output = PlantOutput::LoadPosition;
  c.settings.quantization = 1e-4;
  FlexiblePlant plant(c);
  int distinct = 0;
  double last = 0.0;
  for (int k = 0; k < 3000; ++k) {
    const auto m = plant.step(std::sin(0.003 * k));
    EXPECT_EQ(m.y_exact, m.load_position);
    const double steps = m.y / 1e-4;
    EXPECT_NEAR(steps, std::round(steps), 1e-6);
    EXPECT_LE(std::abs(m.y - m.y_exact), 0.5e-4 + 1e-15);
    if (m.y != last) ++distinct;
    last = m.y;
  }
  EXPECT_GT(distinct, 10);
}

TEST(PlantSensor, NonFiniteCommandIsTreatedAsZero) {
  FlexiblePlant plant(config_of(two_mass(1.0, 2.0, 40.0, 0.2), 0.001));
  const auto m = plant.step(std::nan(""));
  EXPECT_EQ(m.motor_velocity, 0.0);
}

}  // namespace
}  // namespace servotwin::machine
