// Amplitude adaptation law (dissertation C5.11): integrator + relay with hysteresis on THD (and on
// the SNR, issue 25 §1), range
// protection, arbitration decrease > hold > increase.
#include "servotwin/frf/amplitude_adaptation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace servotwin::frf {
namespace {

AmplitudeLaw law() {
  AmplitudeLaw l;
  l.initial = 2.0;
  l.maximum = 5.0;
  l.minimum = 0.1;
  l.rate = 0.25;
  l.thd_threshold = 0.1;
  l.thd_hysteresis = 0.02;
  return l;
}

TEST(AmplitudeAdapter, IntegratorStepsRcTimesInitialAmplitudePerPeriod) {
  // C5.11: A(t) = A(t0) + integral r/Ti, Ti = 2 pi/(rc A(t0) omega): one period with r = 1 adds
  // rc A(t0) = 0.5 (closed form).
  AmplitudeAdapter a(law());
  const int per_period = 400;
  const double omega_ts = 2.0 * std::numbers::pi / per_period;
  for (int k = 0; k < per_period; ++k) a.update(0.5, 0.0, omega_ts);
  EXPECT_NEAR(a.amplitude(), 2.5, 1e-12);
  EXPECT_EQ(a.last_action(), AmplitudeAction::kIncrease);
  for (int k = 0; k < 100 * per_period; ++k) a.update(0.5, 0.0, omega_ts);
  EXPECT_EQ(a.amplitude(), 5.0);  // ceiling, never exceeded
  EXPECT_TRUE(a.blocked());
}

TEST(AmplitudeAdapter, ProportionalGrowthMultipliesByOnePlusRcPerPeriod) {
  // rc A(t) per period: A(t) = A(t0) (1 + rc)^(periods) (closed form): 2 x 1.25^3 after 3 periods.
  AmplitudeLaw l = law();
  l.maximum = 100.0;
  l.proportional = true;
  AmplitudeAdapter a(l);
  const int per_period = 400;
  const double omega_ts = 2.0 * std::numbers::pi / per_period;
  for (int k = 0; k < 3 * per_period; ++k) a.update(0.5, 0.0, omega_ts);
  EXPECT_NEAR(a.amplitude(), 2.0 * std::pow(1.25, 3.0), 1e-9);
}

TEST(AmplitudeAdapter, AStuckMotorsAmplitudeGrowsPerSecondNotPerPeriod) {
  // growth_per_second = 1 while the SNR relay is on: at 1 Hz (1000 samples of 1 ms per period) the
  // amplitude doubles per second, (1 + 1)^t, where rc = 0.25 per period alone gives 1.25^t
  // (closed forms). With the THD relay alone it stays at (1 + rc) per period.
  AmplitudeLaw l = law();
  l.maximum = 1000.0;
  l.proportional = true;
  l.snr_minimum = 3.0;
  l.growth_per_second = 1.0;
  l.ts = 1e-3;
  const double omega_ts = 2.0 * std::numbers::pi * 1e-3;  // 1 Hz
  AmplitudeAdapter stuck(l);
  for (int k = 0; k < 3000; ++k) stuck.update(0.01, 0.0, omega_ts, 0.5);  // SNR 0.5, 3 s
  EXPECT_NEAR(stuck.amplitude(), 2.0 * 8.0, 1e-9);
  AmplitudeAdapter distorted(l);
  for (int k = 0; k < 3000; ++k) distorted.update(0.5, 0.0, omega_ts, 100.0);  // THD 0.5, clean SNR
  EXPECT_NEAR(distorted.amplitude(), 2.0 * std::pow(1.25, 3.0), 1e-9);
  // At 100 Hz rc per period is the faster: 1.25^(100 t), not 2^t.
  AmplitudeAdapter fast(l);
  for (int k = 0; k < 50; ++k) fast.update(0.01, 0.0, 100.0 * omega_ts, 0.5);  // 5 periods
  EXPECT_NEAR(fast.amplitude(), 2.0 * std::pow(1.25, 5.0), 1e-9);
}

TEST(AmplitudeAdapter, RelayHysteresis) {
  // Relay on above THD* + h = 0.12, off below THD* - h = 0.08, holds in between.
  AmplitudeAdapter a(law());
  a.update(0.11, 0.0, 0.01);
  EXPECT_FALSE(a.relay());
  a.update(0.13, 0.0, 0.01);
  EXPECT_TRUE(a.relay());
  a.update(0.09, 0.0, 0.01);
  EXPECT_TRUE(a.relay());  // inside the band: holds
  a.update(0.07, 0.0, 0.01);
  EXPECT_FALSE(a.relay());
  const double before = a.amplitude();
  a.update(0.09, 0.0, 0.01);
  EXPECT_EQ(a.amplitude(), before);
}

TEST(AmplitudeAdapter, LowSnrRaisesTheAmplitudeLikeHighThd) {
  // Issue 25 §1: with SNR* = 3 and hysteresis 0.5, the SNR relay switches on below SNR 3 even at
  // a clean THD, stays on up to SNR 4.5 (3 x 1.5), and off above it.
  AmplitudeLaw l = law();
  l.snr_minimum = 3.0;
  l.snr_hysteresis = 0.5;
  AmplitudeAdapter a(l);
  a.update(0.01, 0.0, 0.01, 10.0);
  EXPECT_FALSE(a.relay());
  const double before = a.amplitude();
  a.update(0.01, 0.0, 0.01, 2.0);
  EXPECT_TRUE(a.relay());
  EXPECT_GT(a.amplitude(), before);
  a.update(0.01, 0.0, 0.01, 4.0);
  EXPECT_TRUE(a.relay());  // inside the band: holds
  a.update(0.01, 0.0, 0.01, 5.0);
  EXPECT_FALSE(a.relay());
  // Each relay keeps its own band: a THD inside the THD band (0.09) does not hold an SNR demand on.
  a.update(0.01, 0.0, 0.01, 2.0);
  EXPECT_TRUE(a.relay());
  a.update(0.09, 0.0, 0.01, 5.0);
  EXPECT_FALSE(a.relay());
  // Unknown SNR (NaN, or the default) makes no demand; without SNR* the SNR is ignored.
  a.update(0.01, 0.0, 0.01, std::nan(""));
  EXPECT_FALSE(a.relay());
  AmplitudeAdapter thd_only(law());
  thd_only.update(0.01, 0.0, 0.01, 0.5);
  EXPECT_FALSE(thd_only.relay());
}

TEST(AmplitudeAdapter, RangeProtectionArbitration) {
  // usage >= 0.8: decrease by 1/2 per period (closed form 2 * 0.5 = 1 after one period), even with
  // the relay on; 0.72 <= usage < 0.8: hold; never below the floor.
  AmplitudeAdapter a(law());
  const int per_period = 200;
  const double omega_ts = 2.0 * std::numbers::pi / per_period;
  for (int k = 0; k < per_period; ++k) a.update(1.0, 0.85, omega_ts);
  EXPECT_NEAR(a.amplitude(), 1.0, 1e-12);
  EXPECT_EQ(a.last_action(), AmplitudeAction::kDecrease);
  a.update(1.0, 0.75, omega_ts);
  EXPECT_EQ(a.last_action(), AmplitudeAction::kHold);
  EXPECT_NEAR(a.amplitude(), 1.0, 1e-12);
  for (int k = 0; k < 100 * per_period; ++k) a.update(1.0, 2.0, omega_ts);
  EXPECT_NEAR(a.amplitude(), 0.1, 1e-12);
  a.update(1.0, std::nan(""), omega_ts);  // unknown usage: never increase
  EXPECT_EQ(a.last_action(), AmplitudeAction::kHold);
}

}  // namespace
}  // namespace servotwin::frf
