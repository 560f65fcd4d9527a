// Display decimation: budgets, extremes, gaps, and path fidelity against closed-form geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "servotwin/core/error.hpp"
#include "servotwin/report/document.hpp"

namespace servotwin::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void expect_strictly_ascending(const std::vector<std::size_t>& idx, std::size_t n) {
  ASSERT_FALSE(idx.empty());
  EXPECT_EQ(idx.front(), 0u);
  EXPECT_EQ(idx.back(), n - 1);
  for (std::size_t i = 1; i < idx.size(); ++i) ASSERT_LT(idx[i - 1], idx[i]) << "at " << i;
}

std::vector<double> noisy_signal(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> y(n);
  for (std::size_t k = 0; k < n; ++k) y[k] = std::sin(static_cast<double>(k) * 1e-3) + 0.1 * noise(rng);
  return y;
}

TEST(DisplayIndices, ShortSeriesAreDrawnWhole) {
  const std::vector<double> y = {3.0, 1.0, 2.0};
  EXPECT_EQ(display_indices(y, 16), (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_TRUE(display_indices({}, 16).empty());
}

TEST(DisplayIndices, RespectsTheBudgetAndKeepsGlobalExtremesAndEnds) {
  for (const std::size_t n : {17u, 1000u, 4001u, 123457u, 600000u}) {
    for (const std::size_t budget : {16u, 17u, 100u, 4000u}) {
      if (n <= budget) continue;
      std::vector<double> y = noisy_signal(n, static_cast<std::uint32_t>(n + budget));
      const std::vector<std::size_t> idx = display_indices(y, budget);
      SCOPED_TRACE(testing::Message() << "n " << n << " budget " << budget);
      EXPECT_LE(idx.size(), budget);
      EXPECT_GE(idx.size(), budget / 2);  // the budget is used, not wasted
      expect_strictly_ascending(idx, n);
      const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
      EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), static_cast<std::size_t>(lo - y.begin())));
      EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), static_cast<std::size_t>(hi - y.begin())));
    }
  }
}

TEST(DisplayIndices, EveryIsolatedSpikeSurvives) {
  // Ten one-sample spikes, up and down, in 600 000 samples of noise: a min/max per bucket keeps
  // each one (a stride or average would lose or flatten them).
  constexpr std::size_t n = 600000;
  std::vector<double> y = noisy_signal(n, 7);
  std::vector<std::size_t> spikes;
  for (std::size_t i = 0; i < 10; ++i) {
    const std::size_t at = 1234 + i * 59873;
    y[at] = (i % 2 == 0 ? 50.0 : -50.0);
    spikes.push_back(at);
  }
  const std::vector<std::size_t> idx = display_indices(y, 4000);
  for (std::size_t at : spikes) EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), at)) << at;
}

TEST(DisplayIndices, GapsStayVisible) {
  constexpr std::size_t n = 100000;
  std::vector<double> y = noisy_signal(n, 3);
  for (std::size_t k = 40000; k < 40003; ++k) y[k] = kNaN;
  y[90000] = std::numeric_limits<double>::infinity();
  const std::vector<std::size_t> idx = display_indices(y, 300);
  EXPECT_LE(idx.size(), 300u);
  expect_strictly_ascending(idx, n);
  EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), std::size_t{40000}));
  EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), std::size_t{90000}));
}

TEST(DisplayIndices, AllNonFiniteSeriesStaysWithinBudget) {
  const std::vector<double> y(50000, kNaN);
  const std::vector<std::size_t> idx = display_indices(y, 64);
  EXPECT_LE(idx.size(), 64u);
  expect_strictly_ascending(idx, y.size());
}

TEST(DisplayIndices, RejectsTinyBudgets) {
  const std::vector<double> y(100, 1.0);
  EXPECT_THROW(display_indices(y, kMinDisplayPoints - 1), core::InputError);
}

/// Largest distance of any original point to the simplified polyline's segment covering it.
double simplification_error(const std::vector<double>& x, const std::vector<double>& y,
                            const std::vector<std::size_t>& idx) {
  double worst = 0.0;
  for (std::size_t s = 0; s + 1 < idx.size(); ++s) {
    const std::size_t a = idx[s], b = idx[s + 1];
    const double vx = x[b] - x[a], vy = y[b] - y[a], l2 = vx * vx + vy * vy;
    for (std::size_t k = a; k <= b; ++k) {
      const double t = l2 > 0 ? std::clamp(((x[k] - x[a]) * vx + (y[k] - y[a]) * vy) / l2, 0.0, 1.0) : 0.0;
      worst = std::max(worst, std::hypot(x[k] - x[a] - t * vx, y[k] - y[a] - t * vy));
    }
  }
  return worst;
}

TEST(DisplayPathIndices, CircleIsDrawnWithinAFewSagittas) {
  // A circle of radius 100 in 200 000 samples drawn with 400 points: the best polygon with m
  // evenly spaced vertices deviates by the sagitta R (1 - cos(pi/m)) = 3.08e-3; the greedy
  // simplification stays within a small multiple of it.
  constexpr std::size_t n = 200000, m = 400;
  constexpr double r = 100.0;
  std::vector<double> x(n), y(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n - 1);
    x[k] = r * std::cos(a);
    y[k] = r * std::sin(a);
  }
  const std::vector<std::size_t> idx = display_path_indices(x, y, m);
  EXPECT_LE(idx.size(), m);
  expect_strictly_ascending(idx, n);
  const double sagitta = r * (1.0 - std::cos(std::numbers::pi / static_cast<double>(m)));
  EXPECT_LT(simplification_error(x, y, idx), 4.0 * sagitta);
}

TEST(DisplayPathIndices, CornersAndReversalsAreKept) {
  // A square traced once, then a back-and-forth move on one line (the reversals are collinear
  // with their neighbours: only the distance to the segment, not to the line, sees them).
  std::vector<double> x, y;
  const auto line_to = [&](double x1, double y1, std::size_t steps) {
    const double x0 = x.empty() ? 0.0 : x.back(), y0 = y.empty() ? 0.0 : y.back();
    for (std::size_t i = 1; i <= steps; ++i) {
      const double t = static_cast<double>(i) / static_cast<double>(steps);
      x.push_back(x0 + t * (x1 - x0));
      y.push_back(y0 + t * (y1 - y0));
    }
  };
  x.push_back(0.0);
  y.push_back(0.0);
  line_to(10.0, 0.0, 20000);
  line_to(10.0, 10.0, 20000);
  line_to(0.0, 10.0, 20000);
  line_to(0.0, 0.0, 20000);
  const std::size_t reversal_1 = x.size() + 9999, reversal_2 = x.size() + 9999 + 15000;
  line_to(-5.0, 0.0, 10000);   // along y = 0, away from the square
  line_to(2.5, 0.0, 15000);    // back through the start
  line_to(-1.0, 0.0, 7000);
  const std::vector<std::size_t> idx = display_path_indices(x, y, 64);
  EXPECT_LE(idx.size(), 64u);
  for (std::size_t corner : {20000u, 40000u, 60000u, 80000u})
    EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), corner)) << corner;
  EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), reversal_1));
  EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), reversal_2));
  EXPECT_LT(simplification_error(x, y, idx), 1e-9);  // piecewise linear: exact
}

TEST(DisplayPathIndices, GapsSplitThePathAndAreKept) {
  constexpr std::size_t n = 30000;
  std::vector<double> x(n), y(n);
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = std::cos(static_cast<double>(k) * 1e-3);
    y[k] = std::sin(static_cast<double>(k) * 7e-4);
  }
  x[10000] = kNaN;
  y[20000] = kNaN;
  y[20001] = kNaN;
  const std::vector<std::size_t> idx = display_path_indices(x, y, 200);
  EXPECT_LE(idx.size(), 200u);
  expect_strictly_ascending(idx, n);
  // The first non-finite sample of each gap and the finite samples around the gaps.
  for (std::size_t k : {9999u, 10000u, 10001u, 19999u, 20000u, 20002u})
    EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), k)) << k;
  EXPECT_FALSE(std::binary_search(idx.begin(), idx.end(), std::size_t{20001}));
}

TEST(DisplayPathIndices, ManyGapsFallBackWithinBudget) {
  constexpr std::size_t n = 100000;
  std::vector<double> x(n), y(n);
  for (std::size_t k = 0; k < n; ++k) {
    x[k] = k % 3 == 0 ? kNaN : static_cast<double>(k);
    y[k] = std::sin(static_cast<double>(k));
  }
  const std::vector<std::size_t> idx = display_path_indices(x, y, 500);
  EXPECT_LE(idx.size(), 500u);
  expect_strictly_ascending(idx, n);
  // The extremes of x survive the fallback.
  EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), std::size_t{1}));
  EXPECT_TRUE(std::binary_search(idx.begin(), idx.end(), std::size_t{99998}));
}

TEST(DisplayPathIndices, LongPathsUseTheCandidatePreselectionAndStayAccurate) {
  // 600 000 samples of a Lissajous figure with 1000 points: longer than 64 x the budget, so the
  // bucket pre-selection runs before the simplification; the result must still be far below a
  // pixel of a 600-pixel chart (extent 2, so 1/300).
  constexpr std::size_t n = 600000, m = 1000;
  std::vector<double> x(n), y(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / static_cast<double>(n) * 2.0 * std::numbers::pi;
    x[k] = std::sin(3.0 * t);
    y[k] = std::sin(4.0 * t);
  }
  const std::vector<std::size_t> idx = display_path_indices(x, y, m);
  EXPECT_LE(idx.size(), m);
  expect_strictly_ascending(idx, n);
  EXPECT_LT(simplification_error(x, y, idx), 1.0 / 300.0);
}

TEST(DisplayPathIndices, RejectsMismatchedLengthsAndTinyBudgets) {
  const std::vector<double> a(10, 0.0), b(11, 0.0);
  EXPECT_THROW(display_path_indices(a, b, 100), core::InputError);
  EXPECT_THROW(display_path_indices(a, a, 3), core::InputError);
}

}  // namespace
}  // namespace servotwin::report
