#include "field_of.hpp"
#include "servotwin/frf/excitation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "servotwin/core/error.hpp"

namespace servotwin::frf {
namespace {

TEST(SineGenerator, FollowsTheAccumulatedPhaseAcrossFrequencyChanges) {
  // Reference: y(k) = A sin(theta_k) + u0 with theta_k = sum_{l<k} omega_l Ts accumulated in long
  // double (closed form of the rotation recursion, C5.1).
  const double ts = 1e-3, amplitude = 2.5, offset = -0.75;
  SineGenerator gen(ts);
  long double theta = 0.0L;
  double worst = 0.0;
  for (int k = 0; k < 200000; ++k) {
    const double omega = k < 70000 ? 12.0 : (k < 140000 ? 31.7 : 5.0 + 1e-4 * (k - 140000));
    const double expected = amplitude * static_cast<double>(std::sin(theta)) + offset;
    worst = std::max(worst, std::abs(gen.output(amplitude, offset) - expected));
    gen.set_frequency(omega);
    gen.advance();
    theta += static_cast<long double>(omega) * static_cast<long double>(ts);
  }
  EXPECT_LT(worst, 1e-9);  // 2e5 rotations: phase error of a few 1e-11 rad
}

TEST(SineGenerator, IsBumplessAndKeepsUnitNorm) {
  // A frequency change never makes the output jump by more than the largest one-sample increment
  // A omega Ts of either frequency (the state is continuous; only the rotation speed changes).
  const double ts = 0.01;
  SineGenerator gen(ts);
  gen.set_frequency(3.0);
  for (int k = 0; k < 1234; ++k) gen.advance();
  const double before = gen.output(1.0, 0.0);
  gen.set_frequency(9.0);
  gen.advance();
  EXPECT_LE(std::abs(gen.output(1.0, 0.0) - before), 9.0 * ts);
  for (int k = 0; k < 5000000; ++k) gen.advance();
  EXPECT_NEAR(std::hypot(gen.sin_phase(), gen.cos_phase()), 1.0, 4e-16);
  gen.reset();
  EXPECT_EQ(gen.sin_phase(), 0.0);
  EXPECT_EQ(gen.cos_phase(), 1.0);
}

TEST(SweepSchedule, LinearAndLogarithmicLaws) {
  // Closed forms: linear omega_k = omega_b + k cp; logarithmic omega(t) = omega_b e^{sc t}.
  const SweepSchedule lin(SweepType::kLinear, 0.01, 0.1, 2.0);
  double w = 0.5;
  for (int k = 0; k < 100; ++k) w = lin.next(w);
  EXPECT_NEAR(w, 1.5, 1e-12);
  for (int k = 0; k < 100; ++k) w = lin.next(w);
  EXPECT_EQ(w, 2.0);  // clipped at omega_end
  EXPECT_NEAR(lin.samples_between(0.5, 1.5), 100.0, 1e-9);

  const SweepSchedule log_sweep(SweepType::kLogarithmic, 0.05, 0.1, 100.0);
  w = 0.2;
  for (int k = 0; k < 400; ++k) w = log_sweep.next(w);
  EXPECT_NEAR(w, 0.2 * std::exp(0.05 * 40.0), 1e-12 * w);
  EXPECT_NEAR(log_sweep.samples_between(0.2, 0.2 * std::exp(2.0)), 400.0, 1e-9);
}

TEST(Excitation, RejectsBadParametersNamingTheField) {
  using test::field_of;
  EXPECT_EQ(field_of([] { SineGenerator g(0.0); }), "ts");
  EXPECT_EQ(field_of([] { SineGenerator g(std::nan("")); }), "ts");
  EXPECT_EQ(field_of([] { SweepSchedule s(SweepType::kLinear, -1.0, 0.1, 1.0); }), "sweep_rate");
  EXPECT_EQ(field_of([] { SweepSchedule s(SweepType::kLinear, 1.0, 0.1, 0.0); }), "omega_end");
}

}  // namespace
}  // namespace servotwin::frf
