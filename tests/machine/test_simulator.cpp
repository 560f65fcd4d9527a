// The virtual machine's time simulation: ideal mode against the exact sampled loop (state
// space, and an independent Python loop), against the continuous Eq. 3.3 model (with the
// sampling error shrinking linearly in ts), and each nonlinearity on its own.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <numeric>
#include <set>
#include <vector>

#include "machine_test_support.hpp"
#include "servotwin/core/error.hpp"
#include "servotwin/machine/closed_loop.hpp"
#include "servotwin/machine/presets.hpp"
#include "servotwin/machine/simulator.hpp"

namespace servotwin::machine {
namespace {
// A namespace of its own: the module's test files are compiled as one translation unit.
namespace simulator_test {

using Complex = std::complex<double>;
using test::reference;
using test::relative_max_difference;
using test::to_vector;
constexpr double kPi = std::numbers::pi;

SimulationOptions ideal() {
  SimulationOptions o;
  o.ideal = true;
  return o;
}

// An axis with every nonlinearity off (so `ideal` changes nothing) except what a test adds.
AxisConfig linear_axis(const char* preset_name) {
  AxisConfig a = preset(preset_name).axes[0];
  a.nonlinear = Nonlinearities{};
  return a;
}

std::vector<double> command(const char* which) { return to_vector(reference()["commands"][which]); }

// ---- ideal mode = exact sampled loop -------------------------------------------------------

TEST(SimulatorIdeal, MatchesTheExactSampledLoop) {
  for (const auto& name : preset_names()) {
    for (const AxisConfig& axis : preset(name).axes) {
      const DiscreteClosedLoop loop = discrete_closed_loop(axis, 1e-3);
      for (const char* which : {"step", "sweep"}) {
        const std::vector<double> cmd = command(which);
        const AxisRun run = simulate_axis(axis, 1e-3, cmd, ideal());
        EXPECT_LT(relative_max_difference(run.act, test::simulate_loop(loop, cmd)), 1e-9) << name << " " << which;
        EXPECT_LT(relative_max_difference(run.u, test::simulate_loop(loop, cmd, {}, 1)), 1e-9) << name << " " << which;
      }
    }
  }
}

TEST(SimulatorIdeal, DelayLineMatchesTheSampledLoopWithDelay) {
  for (const char* name : {"fadal-pid", "fadal-ppi", "fadal-smc", "ballscrew-zpetc"}) {
    AxisConfig axis = linear_axis(name);
    axis.nonlinear.delay_samples = 1;
    const DiscreteClosedLoop loop = discrete_closed_loop(axis, 1e-3, true);
    const std::vector<double> cmd = command("sweep");
    const AxisRun run = simulate_axis(axis, 1e-3, cmd, SimulationOptions{});  // only the delay is on
    EXPECT_LT(relative_max_difference(run.act, test::simulate_loop(loop, cmd)), 1e-9) << name;
    EXPECT_LT(relative_max_difference(run.u, test::simulate_loop(loop, cmd, {}, 1)), 1e-9) << name;
    // The value applied over [k ts, (k+1) ts) was computed one sample earlier: the first
    // sample's control is zero (the axis rests before the start).
    EXPECT_EQ(run.u.front(), 0.0);
  }
}

TEST(SimulatorIdeal, MatchesIndependentPythonLoops) {
  // tools/reference/machine_reference.py: exact ZOH plant from scipy and the controllers'
  // difference equations in a plain loop, gains derived again from the thesis tables.
  for (const char* name : {"fadal-pid", "fadal-ppi", "fadal-smc"}) {
    const AxisConfig axis = preset(name).axes[0];
    for (const char* which : {"step", "sweep"}) {
      const AxisRun run = simulate_axis(axis, 1e-3, command(which), ideal());
      EXPECT_LT(relative_max_difference(run.act, to_vector(reference()["pid_family"][name][which])), 1e-9)
          << name << " " << which;
    }
  }
  const AxisConfig axis = preset("ballscrew-zpetc").axes[0];
  for (const char* which : {"step", "sweep"}) {
    const AxisRun run = simulate_axis(axis, 1e-3, command(which), ideal());
    EXPECT_LT(relative_max_difference(run.act, to_vector(reference()["ballscrew"]["delay0"][which])), 1e-9) << which;
  }
}

TEST(SimulatorIdeal, ZpetcTracksWithZeroPhase) {
  // 10 Hz sine: the ZPETC loop's steady-state response is in phase with the command and its
  // gain is |e^jw - z1|^2/(1 - z1)^2 (Eq. 3.25).
  const AxisConfig axis = preset("ballscrew-zpetc").axes[0];
  const double w = 2 * kPi * 10.0, ts = 1e-3;
  std::vector<double> cmd(3100);  // the last samples' preview reads the held end: not used
  for (std::size_t k = 0; k < cmd.size(); ++k) cmd[k] = std::sin(w * static_cast<double>(k) * ts);
  const AxisRun run = simulate_axis(axis, ts, cmd, ideal());
  Complex acc = 0.0;
  for (std::size_t k = 2000; k < 3000; ++k) acc += run.act[k] * std::exp(Complex(0, -w * static_cast<double>(k) * ts));
  const Complex t = Complex(0, 1) * 2.0 / 1000.0 * acc;
  const double z1 = -0.99937;
  EXPECT_NEAR(t.real(), std::norm(std::exp(Complex(0, w * ts)) - z1) / ((1 - z1) * (1 - z1)), 1e-8);
  EXPECT_NEAR(t.imag(), 0.0, 1e-8);
}

// ---- ideal mode vs the continuous Eq. 3.3 model ---------------------------------------------
//
// Tolerance: the sampled loop is the continuous loop with some signal paths shifted by about
// half a sample (ZOH: Ts/2 lag; backward-difference velocity: Ts/2 lag; backward-Euler
// integral: Ts/2 lead; central differences: none). To first order a shift tau of the reference
// path changes T by j w tau T, of the feedback path by j w tau T S (dT/dtau = -j w T S), so
// |T_sampled - T| <= w Ts (|T| + |T S|); in time, |y_sampled - y| <= Ts (max|x_r'| + max|y'|).
// The second check is that the mismatch is first order: it shrinks ~10x from 1 ms to 0.1 ms.

double smooth_step(double t) {  // 0 -> 1 mm between 10 and 30 ms, quintic blend
  const double u = (t - 0.01) / 0.02;
  if (u <= 0.0) return 0.0;
  if (u >= 1.0) return 1.0;
  return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
}

struct StepComparison {
  double error = 0.0;  // max |y_sim - y_continuous| at the samples
  double bound = 0.0;  // ts (max |x_r'| + max |y'|)
};

StepComparison compare_step(const AxisConfig& axis, double ts) {
  const ClosedLoopCoefficients c = equivalent_closed_loop(axis, ts).coefficients;
  // Continuous reference on a 1 us grid, input sampled at the midpoints (second-order accurate).
  constexpr double fine = 1e-6, duration = 0.4;
  const auto nf = static_cast<Eigen::Index>(duration / fine + 0.5);
  Eigen::MatrixXd u(nf, 1);
  for (Eigen::Index k = 0; k < nf; ++k) u(k, 0) = smooth_step((static_cast<double>(k) + 0.5) * fine);
  const Eigen::MatrixXd y = core::simulate_zoh(core::to_state_space(tracking_tf(c)), u, fine);
  double max_dy = 0.0;
  for (Eigen::Index k = 1; k < nf; ++k) max_dy = std::max(max_dy, std::abs(y(k, 0) - y(k - 1, 0)) / fine);

  const auto n = static_cast<std::size_t>(duration / ts + 0.5);
  const auto stride = static_cast<Eigen::Index>(ts / fine + 0.5);
  std::vector<double> cmd(n);
  for (std::size_t k = 0; k < n; ++k) cmd[k] = smooth_step(static_cast<double>(k) * ts);
  const AxisRun run = simulate_axis(axis, ts, cmd, ideal());
  StepComparison out;
  for (std::size_t k = 0; k < n; ++k)
    out.error = std::max(out.error, std::abs(run.act[k] - y(static_cast<Eigen::Index>(k) * stride, 0)));
  out.bound = ts * (1.875 / 0.02 + max_dy);  // quintic blend: max slope 15/8 per blend time
  return out;
}

// Frequency response of the simulated machine from a sine after 3 s of settling, projected
// over the following second (an integer number of periods for integer-Hz frequencies).
Complex simulated_frf(const AxisConfig& axis, double ts, double hz) {
  const double w = 2 * kPi * hz;
  const auto settle = static_cast<std::size_t>(3.0 / ts + 0.5), window = static_cast<std::size_t>(1.0 / ts + 0.5);
  std::vector<double> cmd(settle + window);
  for (std::size_t k = 0; k < cmd.size(); ++k) cmd[k] = std::sin(w * static_cast<double>(k) * ts);
  const AxisRun run = simulate_axis(axis, ts, cmd, ideal());
  Complex acc = 0.0;
  for (std::size_t k = settle; k < cmd.size(); ++k)
    acc += run.act[k] * std::exp(Complex(0, -w * static_cast<double>(k) * ts));
  return Complex(0, 1) * 2.0 / static_cast<double>(window) * acc;
}

TEST(SimulatorVsContinuous, StepResponseWithinSamplingToleranceAndFirstOrder) {
  for (const char* name : {"fadal-ppi", "fadal-pid", "fadal-smc"}) {
    const AxisConfig axis = preset(name).axes[0];
    const StepComparison coarse = compare_step(axis, 1e-3), fine = compare_step(axis, 1e-4);
    EXPECT_LT(coarse.error, coarse.bound) << name;
    EXPECT_LT(fine.error, fine.bound) << name;
    const double ratio = coarse.error / fine.error;
    EXPECT_GT(ratio, 8.0) << name;
    EXPECT_LT(ratio, 13.0) << name;
  }
}

TEST(SimulatorVsContinuous, FrequencyResponseWithinSamplingToleranceAndFirstOrder) {
  for (const char* name : {"fadal-ppi", "fadal-pid", "fadal-smc"}) {
    const AxisConfig axis = preset(name).axes[0];
    const ClosedLoopCoefficients c = equivalent_closed_loop(axis, 1e-3).coefficients;
    const TwoDofPid law = two_dof_law(axis.controller, axis.plant);
    for (double hz : {1.0, 5.0, 10.0, 20.0, 30.0}) {
      const double w = 2 * kPi * hz;
      const Complex s(0.0, w);
      const Complex t = tracking_tf(c).frequency_response(w);
      const Complex plant = axis.plant.gain / ((axis.plant.inertia * s + axis.plant.damping) * s);
      const Complex sensitivity = 1.0 / (1.0 + plant * ((law.c2 * s + law.c1) * s + law.c0) / s);
      double err[2];
      int i = 0;
      for (double ts : {1e-3, 1e-4}) {
        const Complex sim = simulated_frf(axis, ts, hz);
        // The sine estimate is the exact sampled loop's response (transients have died out).
        const DiscreteTransferFunction exact = discrete_tracking_tf(axis, ts);
        EXPECT_LT(std::abs(sim - exact.frequency_response(w)), 1e-7) << name << " " << hz;
        err[i] = std::abs(sim - t);
        EXPECT_LT(err[i], w * ts * (std::abs(t) + std::abs(t * sensitivity))) << name << " " << hz << " Hz ts " << ts;
        ++i;
      }
      EXPECT_GT(err[0] / err[1], 8.0) << name << " " << hz;
      EXPECT_LT(err[0] / err[1], 13.0) << name << " " << hz;
    }
  }
}

// ---- nonlinearities ----------------------------------------------------------------------------

std::vector<double> move(double from, double to, std::size_t rest, std::size_t ramp, std::size_t hold) {
  std::vector<double> cmd;
  for (std::size_t k = 0; k < rest; ++k) cmd.push_back(from);
  for (std::size_t k = 0; k < ramp; ++k) {
    const double u = static_cast<double>(k + 1) / static_cast<double>(ramp);
    cmd.push_back(from + (to - from) * u * u * (3 - 2 * u));
  }
  for (std::size_t k = 0; k < hold; ++k) cmd.push_back(to);
  return cmd;
}

TEST(SimulatorNonlinear, EncoderQuantizationRoundsToTheNearestCount) {
  AxisConfig axis = linear_axis("fadal-pid");
  axis.nonlinear.encoder_resolution = 0.001;
  SimulationOptions o;
  o.record_states = true;
  const AxisRun run = simulate_axis(axis, 1e-3, command("sweep"), o);
  for (std::size_t k = 0; k < run.act.size(); ++k) {
    const double counts = run.act[k] / 0.001;
    EXPECT_NEAR(counts, std::round(counts), 1e-9) << k;
    EXPECT_LE(std::abs(run.act[k] - run.motor[k]), 0.0005 + 1e-12) << k;
  }
}

TEST(SimulatorNonlinear, EncoderNoiseIsTheDocumentedReproducibleGaussianStream) {
  AxisConfig axis = linear_axis("fadal-pid");
  axis.nonlinear.encoder_noise_std = 0.002;
  SimulationOptions o;
  o.record_states = true;
  const std::vector<double> cmd(200000, 0.0);
  const AxisRun run = simulate_axis(axis, 1e-3, cmd, o, 0);
  // The first deviates equal the Python transcription of mt19937_64 + Box-Muller.
  const auto want = to_vector(reference()["noise"]["seed1_stream0"]);
  for (std::size_t k = 0; k < want.size(); ++k)
    EXPECT_NEAR((run.act[k] - run.motor[k]) / 0.002, want[k], 1e-9) << k;
  // Statistics over 2e5 samples: mean within 4 sigma/sqrt(N), std within 4 sigma/sqrt(2N).
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t k = 0; k < cmd.size(); ++k) {
    const double n = run.act[k] - run.motor[k];
    sum += n;
    sum2 += n * n;
  }
  const double count = static_cast<double>(cmd.size());
  const double mean = sum / count, stddev = std::sqrt(sum2 / count - mean * mean);
  EXPECT_LT(std::abs(mean), 4.0 * 0.002 / std::sqrt(count));
  EXPECT_NEAR(stddev, 0.002, 4.0 * 0.002 / std::sqrt(2.0 * count));
  // Reproducible with the same seed, different with another seed or stream.
  const AxisRun again = simulate_axis(axis, 1e-3, cmd, o, 0);
  EXPECT_EQ(run.act, again.act);
  SimulationOptions other = o;
  other.seed = 42;
  const AxisRun seeded = simulate_axis(axis, 1e-3, cmd, other, 0);
  const auto want42 = to_vector(reference()["noise"]["seed42_stream0"]);
  for (std::size_t k = 0; k < want42.size(); ++k)
    EXPECT_NEAR((seeded.act[k] - seeded.motor[k]) / 0.002, want42[k], 1e-9) << k;
}

TEST(SimulatorNonlinear, MachineAxesUseIndependentNoiseStreams) {
  MachineConfig m = preset("fadal-pid");
  for (auto& a : m.axes) {
    a.nonlinear = Nonlinearities{};
    a.nonlinear.encoder_noise_std = 0.001;
  }
  const std::vector<double> zero(64, 0.0);
  const core::Capture cap = simulate(m, {zero, zero});
  // At k = 0 the axes rest exactly at home: the readings are the first deviates of streams 0, 1.
  EXPECT_NEAR(cap.axes[0].act[0] / 0.001, reference()["noise"]["seed1_stream0"][0].get<double>(), 1e-9);
  EXPECT_NEAR(cap.axes[1].act[0] / 0.001, reference()["noise"]["seed1_stream1"][0].get<double>(), 1e-9);
  EXPECT_NE(cap.axes[0].act, cap.axes[1].act);
}

TEST(SimulatorNonlinear, DacQuantizesToItsCodes) {
  AxisConfig axis = linear_axis("fadal-pid");
  axis.nonlinear.dac_bits = 16;
  axis.nonlinear.dac_range = 10.0;
  const AxisRun run = simulate_axis(axis, 1e-3, command("sweep"));
  const double lsb = 20.0 / 65536.0;
  for (double u : run.u) {
    EXPECT_NEAR(u / lsb, std::round(u / lsb), 1e-9);
    EXPECT_GE(u, -10.0);
    EXPECT_LE(u, 10.0 - lsb);
  }
  // A 3-bit DAC has exactly 8 levels -4/4 ... 3/4 of the range.
  axis.nonlinear.dac_bits = 3;
  axis.nonlinear.dac_range = 4.0;
  const AxisRun coarse = simulate_axis(axis, 1e-3, command("sweep"));
  std::set<double> levels(coarse.u.begin(), coarse.u.end());
  for (double u : levels) EXPECT_TRUE(u == -4 || u == -3 || u == -2 || u == -1 || u == 0 || u == 1 || u == 2 || u == 3) << u;
  EXPECT_GT(levels.size(), 3u);
}

TEST(SimulatorNonlinear, SaturationClipsAndThePlantFollowsTheClippedSignal) {
  AxisConfig axis = linear_axis("fadal-pid");
  axis.nonlinear.u_max = 1.5;
  SimulationOptions o;
  o.record_states = true;
  const std::vector<double> cmd = move(0.0, 5.0, 10, 1, 500);  // a 5 mm jump: saturates hard
  const AxisRun run = simulate_axis(axis, 1e-3, cmd, o);
  const double peak = *std::max_element(run.u.begin(), run.u.end());
  EXPECT_EQ(peak, 1.5);
  EXPECT_GE(*std::min_element(run.u.begin(), run.u.end()), -1.5);
  // While saturated the velocity follows the exact ZOH response to u = 1.5 V.
  const double a = 2.55, kj = 1000.0, e = std::exp(-a * 1e-3), p1 = (1 - e) / a;
  int saturated = 0;
  for (std::size_t k = 11; k + 1 < run.u.size() && run.u[k] == 1.5; ++k, ++saturated)
    EXPECT_NEAR(run.velocity[k + 1], e * run.velocity[k] + p1 * kj * 1.5, 1e-9) << k;
  EXPECT_GT(saturated, 20);
}

TEST(SimulatorNonlinear, BacklashIsAPlayOperator) {
  for (Feedback fb : {Feedback::Motor, Feedback::Table}) {
    AxisConfig axis = linear_axis("fadal-pid");
    axis.nonlinear.backlash.width = 0.05;
    axis.nonlinear.backlash.feedback = fb;
    SimulationOptions o;
    o.record_states = true;
    std::vector<double> cmd = move(0.0, 1.0, 10, 300, 3000);
    const std::vector<double> back = move(1.0, 0.5, 0, 300, 3000);
    cmd.insert(cmd.end(), back.begin(), back.end());
    const AxisRun run = simulate_axis(axis, 1e-3, cmd, o);
    for (std::size_t k = 0; k < cmd.size(); ++k) {
      ASSERT_LE(std::abs(run.motor[k] - run.table[k]), 0.025 + 1e-12) << k;
      // The table moves only when dragged: then the gap is half the play, unless the motor
      // turned back inside the sample (the table stays where the turn left it).
      if (k > 0 && run.table[k] != run.table[k - 1] && std::abs(std::abs(run.motor[k] - run.table[k]) - 0.025) > 1e-12) {
        ASSERT_LE(run.velocity[k - 1] * run.velocity[k], 0.0) << k;
      }
    }
    const std::size_t at_one = 10 + 300 + 2999, at_half = cmd.size() - 1;
    if (fb == Feedback::Motor) {
      // The integral action puts the motor on the command; the table was left half the play
      // behind the motor's extreme position (its overshoot) on the side the axis came from.
      EXPECT_NEAR(run.motor[at_one], 1.0, 1e-6);
      EXPECT_NEAR(run.motor[at_half], 0.5, 1e-6);
      const double peak = *std::max_element(run.motor.begin(), run.motor.begin() + static_cast<long>(at_one));
      const double valley = *std::min_element(run.motor.begin() + static_cast<long>(at_one), run.motor.end());
      EXPECT_NEAR(run.table[at_one], peak - 0.025, 1e-6);
      EXPECT_NEAR(run.table[at_half], valley + 0.025, 1e-6);
    } else {
      // Backlash inside the loop with integral action hunts: a limit cycle in which the table
      // wanders within the play around the command and never settles.
      double lo = 1e9, hi = -1e9;
      for (std::size_t k = at_half - 2000; k <= at_half; ++k) {
        lo = std::min(lo, run.table[k] - 0.5);
        hi = std::max(hi, run.table[k] - 0.5);
      }
      EXPECT_GT(hi - lo, 0.01);
      EXPECT_LT(hi, 0.025 + 1e-3);
      EXPECT_GT(lo, -0.025 - 1e-3);
    }
  }
}

TEST(SimulatorNonlinear, StictionHoldsTheAxisUntilTheControlExceedsIt) {
  // A 1 um step with Coulomb = stiction friction: K kp e = 4.4 N and the derivative kick are far
  // below the 44.1 N stiction, so the axis stays stuck until the integrator has raised K u
  // above the stiction level (about (44.1 - 4.4) / (K ki ts e) = 1250 samples), then moves.
  AxisConfig axis = linear_axis("fadal-pid");
  axis.nonlinear.friction.coulomb_pos = 44.1;
  axis.nonlinear.friction.coulomb_neg = -30.2;
  SimulationOptions o;
  o.record_states = true;
  const AxisRun run = simulate_axis(axis, 1e-3, move(0.0, 0.001, 5, 1, 2000), o);
  std::size_t first_motion = run.motor.size();
  for (std::size_t k = 0; k < run.motor.size(); ++k) {
    if (run.motor[k] != 0.0) {
      first_motion = k;
      break;
    }
  }
  ASSERT_LT(first_motion, run.motor.size());
  for (std::size_t k = 0; k + 1 < first_motion; ++k) EXPECT_LE(100.0 * run.u[k], 44.1) << k;
  EXPECT_GT(100.0 * run.u[first_motion - 1], 44.1);
  EXPECT_GT(first_motion, 1200u);
  EXPECT_LT(first_motion, 1300u);
}

TEST(SimulatorNonlinear, FrictionCausesReversalGlitchesLikeTheModel) {
  // A back-and-forth move: with friction the tracking error jumps at the velocity reversal;
  // its size is set by d0 - d1 (Eq. 3.3's friction step), so it grows with the friction.
  auto peak_error_after_reversal = [](double scale) {
    AxisConfig axis = linear_axis("fadal-pid");
    axis.nonlinear.friction.coulomb_pos = 44.1 * scale;
    axis.nonlinear.friction.coulomb_neg = -30.2 * scale;
    std::vector<double> cmd;
    for (int k = 0; k < 1200; ++k) cmd.push_back(5.0 * std::sin(2 * kPi * 1.0 * k * 1e-3));
    const AxisRun run = simulate_axis(axis, 1e-3, cmd);
    double peak = 0.0;
    for (std::size_t k = 250; k < 400; ++k) peak = std::max(peak, std::abs(cmd[k] - run.act[k]));
    return peak;
  };
  const double none = peak_error_after_reversal(0.0), some = peak_error_after_reversal(1.0),
               more = peak_error_after_reversal(2.0);
  EXPECT_GT(some, 2.0 * none);
  EXPECT_GT(more, 1.5 * some);
}

// ---- machine-level behaviour and input errors ---------------------------------------------------

TEST(Simulator, CaptureEchoesCommandsAndNamesAxes) {
  const MachineConfig m = preset("fadal-smc");
  const std::vector<double> x = command("sweep"), y = command("step");
  const core::Capture cap = simulate(m, {x, y});
  ASSERT_EQ(cap.axes.size(), 2u);
  EXPECT_EQ(cap.axes[0].name, "x");
  EXPECT_EQ(cap.axes[1].name, "y");
  EXPECT_EQ(cap.ts, 1e-3);
  EXPECT_EQ(cap.size(), x.size());
  EXPECT_EQ(cap.axes[0].cmd, x);
  EXPECT_EQ(cap.axes[1].cmd, y);
  EXPECT_EQ(cap.axes[0].u.size(), x.size());
  // act is the 1 um encoder reading.
  for (double v : cap.axes[0].act) EXPECT_NEAR(v / 0.001, std::round(v / 0.001), 1e-9);
  SimulationOptions no_u;
  no_u.record_u = false;
  EXPECT_TRUE(simulate(m, {x, y}, no_u).axes[0].u.empty());
  // Each axis equals its stand-alone simulation.
  EXPECT_EQ(cap.axes[1].act, simulate_axis(m.axes[1], m.ts, y, SimulationOptions{}, 1).act);
}

TEST(Simulator, RejectsMismatchedCommands) {
  const MachineConfig m = preset("fadal-pid");
  const std::vector<double> ok(100, 0.0), short_one(99, 0.0);
  auto field_of = [&](const std::vector<std::vector<double>>& cmds) {
    try {
      simulate(m, cmds);
    } catch (const core::InputError& e) {
      return e.where().field;
    }
    return std::string("no error");
  };
  EXPECT_EQ(field_of({ok}), "commands");
  EXPECT_EQ(field_of({ok, short_one}), "commands[1]");
  std::vector<double> bad = ok;
  bad[17] = std::nan("");
  EXPECT_EQ(field_of({ok, bad}), "commands[1][17]");
  EXPECT_EQ(simulate(m, {std::vector<double>{}, std::vector<double>{}}).size(), 0u);
}

TEST(Simulator, ResultsScaleWithTheLengthUnit) {
  // The same machines in metres (J, B, friction/J and gains per metre) give the same motion.
  for (const char* name : {"fadal-pid", "ballscrew-zpetc"}) {
    AxisConfig mm = preset(name).axes[0];
    mm.nonlinear.encoder_resolution = 0.0;  // rounding to counts is not scale-free at the last bit
    mm.nonlinear.dac_bits = 0;
    AxisConfig m = mm;
    m.plant.inertia *= 1000.0;
    m.plant.damping *= 1000.0;
    std::visit(
        [](auto& c) {
          using T = std::decay_t<decltype(c)>;
          if constexpr (std::is_same_v<T, PidController>) {
            c.kp *= 1000.0;
            c.ki *= 1000.0;
            c.kd *= 1000.0;
          } else if constexpr (std::is_same_v<T, PolePlacementController>) {
            c.kalman_process_noise *= 1e-6;
            c.kalman_measurement_noise *= 1e-6;
          }
        },
        m.controller);
    std::vector<double> cmd_mm = command("sweep"), cmd_m = cmd_mm;
    for (double& v : cmd_m) v *= 1e-3;
    const AxisRun a = simulate_axis(mm, 1e-3, cmd_mm), b = simulate_axis(m, 1e-3, cmd_m);
    std::vector<double> b_mm = b.act;
    for (double& v : b_mm) v *= 1e3;
    EXPECT_LT(relative_max_difference(b_mm, a.act), 1e-9) << name;
  }
}

}  // namespace simulator_test
}  // namespace
}  // namespace servotwin::machine
