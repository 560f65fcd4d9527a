// core::reserve_large is v.reserve(n) plus advice to the kernel: the contents and the capacity are
// those of reserve (checked against the values written), and the advice is harmless on any range.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "servotwin/core/large_buffer.hpp"

namespace {

using servotwin::core::advise_huge_pages;
using servotwin::core::kLargeBufferBytes;
using servotwin::core::reserve_large;

TEST(LargeBuffer, ReserveKeepsContentsAndGivesTheCapacity) {
  std::vector<double> v{1.0, 2.0, 3.0};
  const std::size_t n = 3 * kLargeBufferBytes / sizeof(double);
  reserve_large(v, n);
  EXPECT_GE(v.capacity(), n);
  EXPECT_EQ(v, (std::vector<double>{1.0, 2.0, 3.0}));
  for (std::size_t k = 3; k < n; ++k) v.push_back(static_cast<double>(k));
  EXPECT_EQ(v[n - 1], static_cast<double>(n - 1));
  const double* data = v.data();
  reserve_large(v, n / 2);  // never shrinks, never moves
  EXPECT_EQ(v.data(), data);

  std::vector<std::uint16_t> small;
  reserve_large(small, 10);  // below the threshold: a plain reserve
  EXPECT_GE(small.capacity(), 10U);
}

TEST(LargeBuffer, AdviceOnAnyRangeIsHarmless) {
  std::vector<char> bytes(5 * kLargeBufferBytes + 123, 'a');
  advise_huge_pages(bytes.data() + 1, bytes.size() - 1);  // unaligned start
  advise_huge_pages(bytes.data(), 100);                    // no whole huge page inside
  advise_huge_pages(nullptr, 0);
  for (std::size_t k = 0; k < bytes.size(); k += 4096) ASSERT_EQ(bytes[k], 'a');
}

}  // namespace
