// core::parallel_parts: the parts cover [0, n) once, in contiguous order, and exceptions come back
// in part order. Expected values follow from the definition (counting).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "servotwin/core/parallel.hpp"

namespace {

using servotwin::core::parallel_parts;
using servotwin::core::worker_count;

std::vector<std::pair<std::size_t, std::size_t>> parts_of(std::size_t n, std::size_t workers, std::size_t min_part) {
  std::mutex m;
  std::vector<std::pair<std::size_t, std::size_t>> parts;
  parallel_parts(n, workers, min_part, [&](std::size_t b, std::size_t e) {
    const std::lock_guard<std::mutex> lock(m);
    parts.emplace_back(b, e);
  });
  std::sort(parts.begin(), parts.end());
  return parts;
}

TEST(Parallel, PartsCoverTheRangeOnceAndContiguously) {
  for (std::size_t n : {1U, 2U, 7U, 1000U, 100003U}) {
    for (std::size_t workers : {1U, 2U, 3U, 8U}) {
      const auto parts = parts_of(n, workers, 1);
      ASSERT_FALSE(parts.empty());
      EXPECT_LE(parts.size(), std::min(n, workers));
      EXPECT_EQ(parts.front().first, 0U);
      EXPECT_EQ(parts.back().second, n);
      for (std::size_t i = 1; i < parts.size(); ++i) EXPECT_EQ(parts[i].first, parts[i - 1].second);
      for (const auto& [b, e] : parts) EXPECT_LT(b, e);
    }
  }
  EXPECT_TRUE(parts_of(0, 4, 1).empty());
}

TEST(Parallel, ShortWorkStaysInOnePart) {
  EXPECT_EQ(parts_of(100, 8, 64).size(), 1U);   // 100 / 64 = 1 part
  EXPECT_EQ(parts_of(200, 8, 64).size(), 3U);   // 200 / 64 = 3 parts
  EXPECT_EQ(parts_of(200, 2, 64).size(), 2U);
}

TEST(Parallel, TheFirstFailingPartsExceptionIsRethrownAfterAllFinish) {
  std::atomic<int> finished{0};
  try {
    parallel_parts(4, 4, 1, [&](std::size_t b, std::size_t) {
      finished++;
      if (b >= 1) throw std::runtime_error("part " + std::to_string(b));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "part 1");
  }
  EXPECT_EQ(finished.load(), 4);
}

TEST(Parallel, ZeroWorkersMeansEveryCore) {
  EXPECT_GE(worker_count(0), 1U);
  EXPECT_EQ(worker_count(3), 3U);
}

}  // namespace
