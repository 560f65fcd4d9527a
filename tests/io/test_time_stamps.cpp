// The reader's time column (src/io/time_stamps.hpp): the stamps come back bit for bit in every
// form. Expected values are the stamps pushed; the sizes follow from the representation (two
// bytes a row compact, eight plain).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "time_stamps.hpp"

namespace {

using servotwin::io::detail::TimeStamps;

std::vector<double> replay(const TimeStamps& t) {
  std::vector<double> out;
  t.for_each([&](std::size_t k, double v) {
    EXPECT_EQ(k, out.size());
    out.push_back(v);
  });
  return out;
}

TimeStamps stamps_of(const std::vector<double>& t) {
  TimeStamps s;
  s.reserve(t.size());
  for (double v : t) s.push(v);
  return s;
}

TEST(TimeStamps, DecimalStepsAreKeptInTwoBytesARowAndReplayedExactly) {
  std::vector<double> t;
  for (int k = 0; k < 200000; ++k) t.push_back(12.5 + 0.001 * k);  // steps 0.001 +- rounding
  const TimeStamps s = stamps_of(t);
  EXPECT_EQ(replay(s), t);
  EXPECT_EQ(s.front(), t.front());
  EXPECT_EQ(s.back(), t.back());
  EXPECT_LT(s.bytes(), 3 * t.size());  // compact: 2 bytes a row and a few steps
}

TEST(TimeStamps, StampsAStepCannotGiveBackTurnTheColumnPlain) {
  // Across zero a difference of two stamps is not always exact (Sterbenz's lemma needs
  // t_(k-1) <= t_k <= 2 t_(k-1)): the column goes plain there and still replays exactly.
  std::vector<double> t;
  for (int k = 0; k < 20000; ++k) t.push_back(-0.0101 + 1e-6 * k + 1e-13 * (k % 7));
  const TimeStamps s = stamps_of(t);
  EXPECT_EQ(replay(s), t);
  EXPECT_GE(s.bytes(), 8 * t.size());  // plain
}

TEST(TimeStamps, MoreThan65536DistinctStepsTurnTheColumnPlain) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  std::vector<double> t;
  for (int k = 0; k < 150000; ++k) t.push_back(7.0 + 0.001 * (k + jitter(rng)));
  const TimeStamps s = stamps_of(t);
  EXPECT_EQ(replay(s), t);
  EXPECT_GE(s.bytes(), 8 * t.size());
}

TEST(TimeStamps, SmallAndEmptyColumns) {
  TimeStamps s;
  EXPECT_TRUE(s.empty());
  EXPECT_TRUE(replay(s).empty());
  s.push(1.0);
  EXPECT_EQ(replay(s), std::vector<double>{1.0});
  s.push(1.5);
  EXPECT_EQ(replay(s), (std::vector<double>{1.0, 1.5}));
  EXPECT_EQ(s.size(), 2U);
}

}  // namespace
