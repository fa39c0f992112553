#include "src/solvers/huge_page_allocator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace rig_calibrator {
namespace huge_page_allocator_test {

bool HugePageAligned(const void* memory) {
  return reinterpret_cast<uintptr_t>(memory) % kHugePageBytes == 0;
}

// Below kMinHugePageBytes a block comes from malloc; from it on, 2 MB pages
// (a 2 MB-aligned block that madvise can hand to transparent huge pages).
TEST(HugePageAllocatorTest, LargeBlocksStartOnHugePages) {
  const size_t large = kMinHugePageBytes + 1;
  void* memory = AllocateLarge(large);
  ASSERT_NE(memory, nullptr);
  EXPECT_TRUE(HugePageAligned(memory));
  static_cast<char*>(memory)[large - 1] = 1;  // all of it is usable
  FreeLarge(memory);
  void* small = AllocateLarge(16);
  ASSERT_NE(small, nullptr);
  FreeLarge(small);
  FreeLarge(nullptr);
}

// A LargeVector keeps its values as it grows past kMinHugePageBytes, and
// then lies on huge pages.
TEST(HugePageAllocatorTest, VectorKeepsItsValuesAcrossTheThreshold) {
  LargeVector<int64_t> values;
  const size_t count = 2 * kMinHugePageBytes / sizeof(int64_t);
  for (size_t k = 0; k < count; ++k) values.push_back(static_cast<int64_t>(k));
  EXPECT_TRUE(HugePageAligned(values.data()));
  std::vector<int64_t> expected(count);
  std::iota(expected.begin(), expected.end(), 0);
  EXPECT_TRUE(std::equal(values.begin(), values.end(), expected.begin()));
  LargeVector<int64_t> copy = values;
  EXPECT_EQ(copy, values);
}

}  // namespace huge_page_allocator_test
}  // namespace rig_calibrator
