// The settling test on windows of half-period means (frf/settle_windows.hpp, issue 25 §1).
// References are closed forms of the sequences fed in: the means of alternating or rotating
// deviations over whole cycles, and their spread.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "servotwin/frf/settle_windows.hpp"

namespace servotwin::frf {
namespace {
namespace settle_windows_test {

using Complex = std::complex<double>;

/// Feeds one half period whose every sample is `value`.
void half_period(SettleWindows& w, Complex value, int samples = 10) {
  for (int i = 0; i < samples; ++i) w.add(value);
  w.close_half_period();
}

TEST(SettleWindows, NoiseThatAlternatesAveragesOutOverTwoHalfPeriods) {
  // P = 2 − j with ±1 % alternating between half periods: single estimates half a period apart
  // differ by 2 %, far above a 0.25 % bound; the means of two half periods are exactly P, so two
  // windows of two agree, and their spread over √2 (1 %·|P|) is within twice a bound of 0.6 %.
  const Complex p(2.0, -1.0);
  SettleWindows w;
  for (int k = 0; k < 4; ++k) half_period(w, p * (1.0 + (k % 2 == 0 ? 0.01 : -0.01)));
  const SettleWindows::Verdict v = w.test(0.006, 0.0, 64);
  ASSERT_TRUE(v.settled);
  EXPECT_LT(std::abs(v.mean - p), 1e-15);
  // A bound of 0.4 % lets the windows agree but not the standard error (1 % > 2 × 0.4 %).
  EXPECT_FALSE(w.test(0.004, 0.0, 64).settled);
}

TEST(SettleWindows, ARingingBeatPassesOnlyWhenItsSpreadIsSmall) {
  // A beat of amplitude a rotating once per 8 half periods on P = 1: windows of 8 hold whole
  // cycles, so their means are exactly P; the spread of the 8 half-period means is a (each sits at
  // distance a), the standard error a·sqrt(8/7)/√8 = a/√7. Bound 0.01: a = 0.06 gives 0.0227 >
  // 0.02 (refused), a = 0.04 gives 0.0151 (settled, mean P).
  for (const auto& [a, settles] : {std::pair{0.06, false}, std::pair{0.04, true}}) {
    SettleWindows w;
    for (int k = 0; k < 16; ++k) half_period(w, 1.0 + a * std::polar(1.0, 2.0 * std::numbers::pi * k / 8.0));
    const SettleWindows::Verdict v = w.test(0.01, 0.0, 8);
    EXPECT_EQ(v.settled, settles) << a;
    if (settles) {
      EXPECT_NEAR(v.mean.real(), 1.0, 1e-12);
      EXPECT_NEAR(v.mean.imag(), 0.0, 1e-12);
    }
  }
}

TEST(SettleWindows, ATransientThatStillDecaysIsNotSettled) {
  // P(1 + e^{-k/4}): the last two windows of any length differ by more than 0.5 % of P while
  // the transient is above a few per cent; the absolute allowance (noise) is what lets a point
  // that small settle.
  SettleWindows w;
  for (int k = 0; k < 12; ++k) half_period(w, 1.0 + std::exp(-k / 4.0));
  EXPECT_FALSE(w.test(0.005, 0.0, 64).settled);
  EXPECT_TRUE(w.test(0.005, 1.0, 64).settled);
}

TEST(SettleWindows, WindowsNeverExceedTheirLimitOrTheStoredMeans) {
  // Three means stored: no window of 2 has a previous window of 2, so nothing settles; with a
  // window limit of 1 never. The longest mean of three stored is that of the newest two; of one
  // stored, the fallback.
  SettleWindows w;
  for (int k = 0; k < 3; ++k) half_period(w, Complex(k, 0.0));
  EXPECT_FALSE(w.test(1.0, 1.0, 64).settled);
  half_period(w, 3.0);
  EXPECT_TRUE(w.test(1.0, 10.0, 64).settled);
  EXPECT_FALSE(w.test(1.0, 10.0, 1).settled);
  EXPECT_EQ(w.longest_mean(64, 9.0), Complex(1.5, 0.0));  // (0 + 1 + 2 + 3)/4
  EXPECT_EQ(w.longest_mean(2, 9.0), Complex(2.5, 0.0));
  w.clear();
  half_period(w, 5.0);
  EXPECT_EQ(w.longest_mean(64, 9.0), Complex(9.0, 0.0));
  // A half period without samples stores nothing.
  w.close_half_period();
  EXPECT_EQ(w.count(), 1u);
}

TEST(SettleWindows, TheRingKeepsTheNewestMeans) {
  // More half periods than the capacity, the count not a multiple of it, each mean its own index
  // k: a window of the newest w has the mean of the w largest indices, (2N + 36 − 1) − (w − 1)/2,
  // and the previous window's is w lower; the longest window (the capacity) reaches the oldest
  // kept mean.
  constexpr std::size_t n = SettleWindows::kCapacity, pushed = 2 * n + 36;
  SettleWindows w;
  for (std::size_t k = 0; k < pushed; ++k) half_period(w, Complex(static_cast<double>(k), 1.0), 1);
  EXPECT_EQ(w.count(), n);
  for (std::size_t window : {2u, 8u, 64u, 256u}) {
    const double newest = static_cast<double>(pushed - 1);
    EXPECT_NEAR(w.longest_mean(window, 0.0).real(), newest - (static_cast<double>(window) - 1.0) / 2.0, 1e-9) << window;
    EXPECT_NEAR(w.longest_mean(window, 0.0).imag(), 1.0, 1e-12) << window;
  }
  EXPECT_NEAR(w.longest_mean(n, 0.0).real(), static_cast<double>(pushed - 1) - (static_cast<double>(n) - 1.0) / 2.0, 1e-9);
  // Consecutive windows of w differ by w. Absolute bound 3: w = 2 passes (|Δ| = 2; its two means
  // k − 1, k have standard error 0.5 ≤ 6) with mean k − 1/2; bound 1.5: no window passes.
  const SettleWindows::Verdict v = w.test(0.0, 3.0, 128);
  ASSERT_TRUE(v.settled);
  EXPECT_NEAR(v.mean.real(), static_cast<double>(pushed - 1) - 0.5, 1e-9);  // w = 2: |Δ| = 2 ≤ 3
  EXPECT_FALSE(w.test(0.0, 1.5, 128).settled);                               // every |Δ| = w ≥ 2
}

}  // namespace settle_windows_test
}  // namespace
}  // namespace servotwin::frf
