// AxisModel::simulate: the linear model against scipy.signal.lsim, friction switching against a
// solve_ivp event integrator (both in tools/reference/axis_model_reference.py), the undamped
// Coulomb oscillator in closed form, and the properties the issue asks for (no chatter, holding
// at rest, unit invariance, robustness for unstable and sign-inconsistent models).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/rapid/axis_model.hpp"
#include "test_axis_model_support.hpp"

namespace servotwin::rapid {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace axis_model_simulation_test {

using test::doubles;
using test::reference_model;
using test::simulation_case;

constexpr double kTs = 1e-3;

double max_abs(const std::vector<double>& v) {
  double m = 0.0;
  for (const double x : v) m = std::max(m, std::abs(x));
  return m;
}

// Largest |a - b| relative to max |b|.
double relative_deviation(const std::vector<double>& a, const std::vector<double>& b) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst / max_abs(b);
}

// Changes of sign of the nonzero velocity samples.
int direction_changes(const std::vector<double>& velocity) {
  int changes = 0, last = 0;
  for (const double v : velocity) {
    const int s = (v > 0) - (v < 0);
    if (s == 0) continue;
    if (last != 0 && s != last) ++changes;
    last = s;
  }
  return changes;
}

ModelSimulationOptions fixture_start(const nlohmann::json& c) {
  ModelSimulationOptions o;
  o.initial_position = c.at("x0").get<double>();
  o.initial_integrator = c.at("ei0").get<double>();
  return o;
}

class LinearAgainstLsim : public ::testing::TestWithParam<std::string> {};

TEST_P(LinearAgainstLsim, MatchesHeldInputLsim) {
  const auto& c = simulation_case("linear", GetParam());
  const AxisModel m(test::coefficients_from_json(c.at("model")), kTs);
  const std::vector<double> command = doubles(c.at("command"));
  const ModelResponse r = m.simulate(command, fixture_start(c));
  // Both integrate exactly (matrix exponentials); observed agreement ~1e-14.
  EXPECT_LT(relative_deviation(r.position, doubles(c.at("position"))), 1e-11);
  EXPECT_LT(relative_deviation(r.velocity, doubles(c.at("velocity"))), 1e-10);
  for (std::size_t k = 0; k < command.size(); ++k) ASSERT_EQ(r.tracking_error[k], command[k] - r.position[k]);
}

INSTANTIATE_TEST_SUITE_P(AxisModelSimulation, LinearAgainstLsim,
                         ::testing::Values("pid_moves", "ppi_offset", "smc_constant_friction", "no_integrator",
                                           "unstable", "ppi_estimated_off_equilibrium", "b_only", "static_error"));

TEST(AxisModelSimulation, DefaultStartIsTheRestStateOfTheFirstCommand) {
  // ppi_offset starts at x_r = 100 with b2 != a2; the fixture used x(0) = x_r,0 and
  // a3 e_i(0) = a2 x(0) - b2 x_r,0, the documented default.
  const auto& c = simulation_case("linear", "ppi_offset");
  const AxisModel m(test::coefficients_from_json(c.at("model")), kTs);
  const ModelResponse r = m.simulate(doubles(c.at("command")));
  EXPECT_LT(relative_deviation(r.position, doubles(c.at("position"))), 1e-9);
  // Before the first move (50 ms dwell) the model rests exactly where it started.
  for (std::size_t k = 0; k < 45; ++k) EXPECT_NEAR(r.position[k], 100.0, 1e-12) << k;
  // Without integrator and with b2 != a2 the rest position carries the static error b2/a2.
  const auto& p = simulation_case("linear", "static_error");
  const AxisModel q(test::coefficients_from_json(p.at("model")), kTs);
  const ModelResponse rq = q.simulate(doubles(p.at("command")));
  EXPECT_LT(relative_deviation(rq.position, doubles(p.at("position"))), 1e-11);
  for (std::size_t k = 0; k < 45; ++k) EXPECT_NEAR(rq.position[k], 100.0 * 20000.0 / 25000.0, 1e-12) << k;
}

TEST(AxisModelSimulation, UnstableModelIsSimulatedAndReportedUnstable) {
  const AxisModel m(reference_model("unstable"), kTs);
  EXPECT_FALSE(m.is_stable());
  const auto& c = simulation_case("linear", "unstable");
  const ModelResponse r = m.simulate(doubles(c.at("command")), fixture_start(c));
  // The growing oscillation e^(2 t) is reproduced (checked against lsim above); it is large at the
  // end but finite.
  EXPECT_TRUE(std::isfinite(r.position.back()));
}

class FrictionAgainstEventIntegrator : public ::testing::TestWithParam<std::string> {};

TEST_P(FrictionAgainstEventIntegrator, MatchesSolveIvpWithEvents) {
  const auto& c = simulation_case("friction", GetParam());
  const AxisModel m(test::coefficients_from_json(c.at("model")), kTs);
  const ModelResponse r = m.simulate(doubles(c.at("command")), fixture_start(c));
  // solve_ivp (DOP853, rtol 1e-13) with event location; observed agreement 1e-14 (positions)
  // and 1e-12 (velocities) relative to their maxima.
  EXPECT_LT(relative_deviation(r.position, doubles(c.at("position"))), 1e-11);
  EXPECT_LT(relative_deviation(r.velocity, doubles(c.at("velocity"))), 1e-10);
  EXPECT_EQ(r.events.reversals, c.at("reversals").get<std::uint64_t>());
  EXPECT_EQ(r.events.event_limit_hits, 0u);
}

INSTANTIATE_TEST_SUITE_P(AxisModelSimulation, FrictionAgainstEventIntegrator,
                         ::testing::Values("pid_reversal", "ppi_moves", "smc_moves", "no_integrator_offset",
                                           "ppi_estimated_moves", "inverted_band"));

// Undamped Coulomb oscillator x'' = w^2 (X - x) - F, F = +-D: each half period pi/w is a cosine
// about X -+ D/w^2, the amplitude about X shrinks by 2 D/w^2 per half period, and the mass sticks
// at the first turning point within D/w^2 of X.
std::vector<double> coulomb_oscillator(double w, double target, double delta, std::size_t n, double ts,
                                       int* half_periods) {
  std::vector<double> x(n);
  double start = 0.0, t0 = 0.0, dir = target > 0 ? 1.0 : -1.0;
  bool stuck = false;
  *half_periods = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * ts;
    while (!stuck && t >= t0 + std::numbers::pi / w) {  // next turning point
      const double centre = target - dir * delta;
      start = 2.0 * centre - start;
      t0 += std::numbers::pi / w;
      ++*half_periods;
      dir = -dir;
      stuck = std::abs(target - start) <= delta;
    }
    if (stuck) {
      x[k] = start;
    } else {
      const double centre = target - dir * delta;
      x[k] = centre + (start - centre) * std::cos(w * (t - t0));
    }
  }
  return x;
}

void check_coulomb_oscillator(double freq_hz) {
  const double w = 2 * std::numbers::pi * freq_hz, target = 1.0, delta = 0.07;
  const double d = delta * w * w;
  const AxisModel m({.a1 = 0.0, .a2 = w * w, .a3 = 0.0, .b2 = w * w, .d0 = d, .d1 = -d}, kTs);
  const std::vector<double> command(600, target);
  ModelSimulationOptions o;
  o.initial_position = 0.0;
  const ModelResponse r = m.simulate(command, o);
  int half_periods = 0;
  const std::vector<double> expected = coulomb_oscillator(w, target, delta, command.size(), kTs, &half_periods);
  for (std::size_t k = 0; k < command.size(); ++k) ASSERT_NEAR(r.position[k], expected[k], 1e-11) << "sample " << k;
  EXPECT_EQ(half_periods, 7);  // 0.93, 0.86, 0.72, 0.58, 0.44, 0.30, 0.16 -> rest within 0.07
  EXPECT_EQ(r.events.reversals, 6u);
  EXPECT_EQ(r.events.sticks, 1u);
  EXPECT_EQ(r.events.breakaways, 1u);
  EXPECT_EQ(r.velocity.back(), 0.0);
}

TEST(AxisModelSimulation, CoulombOscillatorClosedFormTurningPointsOnSamples) {
  check_coulomb_oscillator(10.0);  // half period 50 ms: every turning point falls on a sample
}

TEST(AxisModelSimulation, CoulombOscillatorClosedFormTurningPointsInsideSamples) {
  check_coulomb_oscillator(9.7);
}

// Shortest run of samples with one velocity sign (zeros count with the run they interrupt):
// chatter would show as runs of one or two samples.
std::size_t shortest_direction_run(const std::vector<double>& velocity) {
  int last = 0;
  std::size_t run = 0, shortest = velocity.size();
  for (const double v : velocity) {
    const int s = (v > 0) - (v < 0);
    if (s == last || s == 0) {
      ++run;
      continue;
    }
    if (last != 0) shortest = std::min(shortest, run);
    last = s;
    run = 1;
  }
  return shortest;
}

TEST(AxisModelSimulation, ReversalSwitchesDirectionExactlyOnce) {
  // PID X with friction, a move out and straight back. Around the command's reversal at
  // t = 0.2 s the model's velocity changes sign exactly once (no chatter). (At the very end the
  // underdamped model overshoots the final target: that is a second, separate reversal.)
  const AxisModel m(reference_model("pid_x_actual"), kTs);
  const std::vector<double> command = test::back_and_forth(10.0, 100.0, 1000.0, kTs, 0.0, 1);
  const ModelResponse r = m.simulate(command);
  const std::vector<double> middle(r.velocity.begin() + 100, r.velocity.begin() + 300);
  EXPECT_EQ(direction_changes(middle), 1);
  EXPECT_EQ(static_cast<std::uint64_t>(direction_changes(r.velocity)), r.events.reversals);
  EXPECT_EQ(r.events.event_limit_hits, 0u);
  // The switch happens within a few samples of the command's reversal.
  std::size_t switch_at = 0;
  for (std::size_t k = 1; k < 300; ++k)
    if (r.velocity[k - 1] > 0 && r.velocity[k] < 0) switch_at = k;
  EXPECT_NEAR(static_cast<double>(switch_at), 200.0, 5.0);
}

TEST(AxisModelSimulation, NoChatterAtReversalsAndStops) {
  // The underdamped PID X (zeta 0.45) overshoots each target, creeps back and sticks; then the
  // integrator breaks it away. Every direction, once taken, lasts many samples, and every
  // reversal seen in the samples is one counted event.
  const AxisModel m(reference_model("pid_x_actual"), kTs);
  const std::vector<double> command = test::back_and_forth(10.0, 100.0, 1000.0, kTs, 0.3, 3);
  const ModelResponse r = m.simulate(command);
  EXPECT_GE(shortest_direction_run(r.velocity), 10u);
  EXPECT_EQ(static_cast<std::uint64_t>(direction_changes(r.velocity)), r.events.reversals);
  EXPECT_GE(r.events.sticks, 6u);  // at least once after every move
  EXPECT_EQ(r.events.event_limit_hits, 0u);
  // Sinusoidal command: command reversals at t = 0.125 + 0.25 j s, j = 0..11, before the end
  // at 3 s; the model follows with one direction change each.
  std::vector<double> sine(3000);
  for (std::size_t k = 0; k < sine.size(); ++k) sine[k] = 2.0 * std::sin(2 * std::numbers::pi * 2.0 * kTs * static_cast<double>(k));
  const ModelResponse q = m.simulate(sine);
  EXPECT_EQ(q.events.reversals, 12u);
  EXPECT_EQ(direction_changes(q.velocity), 12);
  EXPECT_GE(shortest_direction_run(q.velocity), 120u);  // first run: a quarter period
}

TEST(AxisModelSimulation, StuckAxisHoldsUntilTheIntegratorBreaksItAway) {
  // PID X at rest at 0, command steps by delta at t = 0.1 s. Once the difference stencils have
  // passed (k >= step + 3), the net drive is g = a2 delta + a3 delta t' (t' from the step): the
  // axis holds exactly while g < d0 and breaks away at t' = (d0 - a2 delta)/(a3 delta).
  const ModelCoefficients c = reference_model("pid_x_actual");
  const AxisModel m(c, kTs);
  const double delta = 1e-3;
  std::vector<double> command(2000, 0.0);
  for (std::size_t k = 100; k < command.size(); ++k) command[k] = delta;
  const ModelResponse r = m.simulate(command);
  const double t_break = 0.1 + (c.d0 - c.a2 * delta) / (c.a3 * delta);  // 1.2533 s
  for (std::size_t k = 0; k < command.size(); ++k) {
    const double t = static_cast<double>(k) * kTs;
    if (t <= t_break) {
      ASSERT_EQ(r.position[k], 0.0) << "moved at t = " << t;
      ASSERT_EQ(r.velocity[k], 0.0);
    }
    if (t > t_break + 2 * kTs) {
      ASSERT_GT(r.position[k], 0.0) << "still stuck at t = " << t;
    }
  }
  EXPECT_EQ(r.events.breakaways, 1u);
  // Without integrator nothing ever changes the net drive: the axis holds for good.
  const AxisModel p({.a1 = 150.0, .a2 = 30000.0, .a3 = 0.0, .b2 = 30000.0, .d0 = 200.0, .d1 = -150.0}, kTs);
  std::vector<double> small(3000, 0.0);
  for (std::size_t k = 10; k < small.size(); ++k) small[k] = 0.004;  // a2 delta = 120 < 200
  const ModelResponse q = p.simulate(small);
  EXPECT_EQ(max_abs(q.position), 0.0);
  EXPECT_EQ(q.events.breakaways, 0u);
}

TEST(AxisModelSimulation, UnitsScaleOnlyPositions) {
  // mm -> m: lengths and friction (length/s^2) scale by 1e-3, coefficients a, b do not.
  ModelCoefficients mm = reference_model("ppi_x_actual");
  ModelCoefficients m = mm;
  m.d0 *= 1e-3;
  m.d1 *= 1e-3;
  const auto& c = simulation_case("friction", "ppi_moves");
  const std::vector<double> command_mm = doubles(c.at("command"));
  std::vector<double> command_m(command_mm.size());
  std::transform(command_mm.begin(), command_mm.end(), command_m.begin(), [](double x) { return x * 1e-3; });
  const ModelResponse r_mm = AxisModel(mm, kTs).simulate(command_mm);
  const ModelResponse r_m = AxisModel(m, kTs).simulate(command_m);
  std::vector<double> back(r_m.position.size());
  std::transform(r_m.position.begin(), r_m.position.end(), back.begin(), [](double x) { return x * 1e3; });
  EXPECT_LT(relative_deviation(back, r_mm.position), 1e-12);
  EXPECT_EQ(r_m.events.reversals, r_mm.events.reversals);
  EXPECT_EQ(r_m.events.sticks, r_mm.events.sticks);
  EXPECT_EQ(r_m.events.breakaways, r_mm.events.breakaways);
  // An offset of the whole trajectory only offsets the response.
  std::vector<double> shifted = command_mm;
  for (double& x : shifted) x += 250.0;
  const ModelResponse r_off = AxisModel(mm, kTs).simulate(shifted);
  double worst = 0.0;
  for (std::size_t k = 0; k < shifted.size(); ++k) worst = std::max(worst, std::abs(r_off.position[k] - 250.0 - r_mm.position[k]));
  EXPECT_LT(worst, 1e-9 * 250.0);
  EXPECT_EQ(r_off.events.reversals, r_mm.events.reversals);
}

TEST(AxisModelSimulation, CommandShiftDrivesWithTheShiftedCommand) {
  const AxisModel m(reference_model("pid_x_actual"), kTs);
  const std::vector<double> command = test::back_and_forth(5.0, 80.0, 800.0, kTs, 0.05, 2);
  std::vector<double> shifted(command.size());
  for (std::size_t k = 0; k < command.size(); ++k) shifted[k] = command[std::min(k + 2, command.size() - 1)];
  ModelSimulationOptions o;
  o.command_shift = 2;
  const ModelResponse a = m.simulate(command, o);
  const ModelResponse b = m.simulate(shifted);
  for (std::size_t k = 0; k < command.size(); ++k) {
    ASSERT_EQ(a.position[k], b.position[k]);
    ASSERT_EQ(a.tracking_error[k], command[k] - a.position[k]);  // error against the unshifted command
  }
}

TEST(AxisModelSimulation, SignInconsistentFrictionTerminatesWithoutChatter) {
  // d0 < 0 < d1: no rest state exists and the model limit-cycles; it must neither hang nor
  // switch direction more often than its motion allows (each direction lasts several samples).
  ModelCoefficients c = reference_model("pid_x_actual");
  c.d0 = -200.0;
  c.d1 = 300.0;
  const std::vector<double> command = test::back_and_forth(10.0, 100.0, 1000.0, kTs, 0.2, 3);
  const ModelResponse r = AxisModel(c, kTs).simulate(command);
  EXPECT_EQ(r.events.event_limit_hits, 0u);
  EXPECT_EQ(r.events.sticks, 0u);
  EXPECT_GE(shortest_direction_run(r.velocity), 5u);
  for (const double x : r.position) ASSERT_TRUE(std::isfinite(x));
  // Both friction values positive (d1 > 0 but d1 <= d0): an ordinary, shifted stick band.
  c.d0 = 300.0;
  c.d1 = 100.0;
  const ModelResponse q = AxisModel(c, kTs).simulate(command);
  EXPECT_EQ(q.events.event_limit_hits, 0u);
  EXPECT_GE(shortest_direction_run(q.velocity), 5u);
  EXPECT_EQ(static_cast<std::uint64_t>(direction_changes(q.velocity)), q.events.reversals);
}

TEST(AxisModelSimulation, BadInputAndDegenerateCases) {
  const AxisModel m(reference_model("pid_x_actual"), kTs);
  EXPECT_TRUE(m.simulate(std::vector<double>{}).position.empty());
  const ModelResponse one = m.simulate(std::vector<double>{3.0});
  ASSERT_EQ(one.position.size(), 1u);
  EXPECT_EQ(one.position[0], 3.0);
  std::vector<double> bad(10, 0.0);
  bad[7] = std::numeric_limits<double>::quiet_NaN();
  try {
    (void)m.simulate(bad);
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "command[7]");
  }
  ModelSimulationOptions o;
  o.initial_integrator = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)m.simulate(std::vector<double>(5, 0.0), o), core::InputError);
  // Growth beyond exp(700) per sample: the ZOH matrices overflow; reported, not simulated.
  const AxisModel exploding({.a1 = -1e6, .a2 = 1.0, .a3 = 1.0, .b2 = 1.0}, kTs);
  EXPECT_FALSE(exploding.is_stable());
  EXPECT_THROW((void)exploding.simulate(std::vector<double>(5, 0.0)), core::InputError);
}

TEST(AxisModelSimulation, ModelsFarBeyondNyquistAreRefusedWithFrictionAndSimulatedWithout) {
  // Issue 26: the thesis's PID model scaled by 1e6 (a1 ts = 1.9e5: the event search would need
  // that many series pieces per friction event) made predict run for minutes. With friction it is
  // refused, naming a1 and the speed; without friction it is a plain ZOH simulation. Scaled by
  // 1e4 (a2 ts^2 + a1 ts + a3 ts^3 = 2.4e3) it is still simulated, in bounded time.
  ModelCoefficients c = reference_model("pid_x_actual");
  for (double* a : {&c.a1, &c.a2, &c.a3, &c.b0, &c.b1, &c.b2, &c.d0, &c.d1}) *a *= 1e6;
  std::vector<double> circle;
  for (int k = 0; k < 1300; ++k) circle.push_back(10.0 * std::sin(2.0 * std::numbers::pi * k / 1300.0));
  try {
    (void)AxisModel(c, kTs).simulate(circle);
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    EXPECT_EQ(e.where().field, "a1");
    EXPECT_NE(std::string(e.what()).find("times faster than its sample period"), std::string::npos) << e.what();
  }
  c.d0 = c.d1 = 0.0;
  EXPECT_EQ(AxisModel(c, kTs).simulate(circle).position.size(), circle.size());
  ModelCoefficients moderate = reference_model("pid_x_actual");
  for (double* a : {&moderate.a1, &moderate.a2, &moderate.a3, &moderate.b0, &moderate.b1, &moderate.b2, &moderate.d0,
                    &moderate.d1})
    *a *= 1e4;
  const ModelResponse r = AxisModel(moderate, kTs).simulate(circle);
  EXPECT_GE(r.events.reversals, 1u);
  ModelSimulationOptions every_sample;
  every_sample.event_search_every_sample = true;
  const ModelResponse ref = AxisModel(moderate, kTs).simulate(circle, every_sample);
  double rms = 0.0;
  for (double e : ref.tracking_error) rms += e * e;
  rms = std::sqrt(rms / static_cast<double>(circle.size()));
  for (std::size_t k = 0; k < circle.size(); ++k) EXPECT_NEAR(r.tracking_error[k], ref.tracking_error[k], 1e-9 * rms) << k;
}

}  // namespace axis_model_simulation_test
}  // namespace
}  // namespace servotwin::rapid
