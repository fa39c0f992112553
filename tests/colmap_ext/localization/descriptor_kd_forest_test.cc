#include "colmap_ext/localization/descriptor_kd_forest.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <thread>
#include <vector>

namespace rig_calibrator {
namespace descriptor_kd_forest_test {

colmap::FeatureDescriptors RandomDescriptors(const int rows,
                                             const unsigned int seed) {
  std::mt19937 generator(seed);
  std::uniform_int_distribution<int> value(0, 255);
  colmap::FeatureDescriptors descriptors(rows, 128);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < 128; ++c) descriptors(r, c) = value(generator);
  }
  return descriptors;
}

long SquaredDistance(const colmap::FeatureDescriptors& a, const int row_a,
                     const colmap::FeatureDescriptors& b, const int row_b) {
  long sum = 0;
  for (int c = 0; c < 128; ++c) {
    const long d = static_cast<long>(a(row_a, c)) - b(row_b, c);
    sum += d * d;
  }
  return sum;
}

// With as many checks as leaves the search is exact, so every query's nearest
// must be the brute-force nearest. The visited set is reused across queries
// (and across forests) on a thread: a bit left set by an earlier query would
// skip a leaf and break this.
void ExpectExactNearest(const DescriptorKdForest& forest,
                        const colmap::FeatureDescriptors& data,
                        const colmap::FeatureDescriptors& queries) {
  DescriptorKdForest::IndexMatrix indices;
  forest.KnnSearch(queries, 1, static_cast<int>(data.rows()) * 4, &indices);
  for (int q = 0; q < queries.rows(); ++q) {
    long best = std::numeric_limits<long>::max();
    for (int r = 0; r < data.rows(); ++r) {
      best = std::min(best, SquaredDistance(queries, q, data, r));
    }
    ASSERT_GE(indices(q, 0), 0) << "query " << q;
    EXPECT_EQ(SquaredDistance(queries, q, data, indices(q, 0)), best)
        << "query " << q;
  }
}

TEST(DescriptorKdForestTest, ExactSearchOnReusedVisitedSetsAcrossForests) {
  const colmap::FeatureDescriptors large = RandomDescriptors(3000, 1);
  const colmap::FeatureDescriptors small = RandomDescriptors(200, 2);
  const colmap::FeatureDescriptors queries = RandomDescriptors(50, 3);
  const DescriptorKdForest large_forest(large, 4, 0);
  const DescriptorKdForest small_forest(small, 4, 0);
  ExpectExactNearest(large_forest, large, queries);
  ExpectExactNearest(small_forest, small, queries);
  ExpectExactNearest(large_forest, large, queries);
}

TEST(DescriptorKdForestTest, SameNeighboursOnEveryThread) {
  const colmap::FeatureDescriptors data = RandomDescriptors(5000, 4);
  const colmap::FeatureDescriptors queries = RandomDescriptors(300, 5);
  const DescriptorKdForest forest(data, 4, 0);
  DescriptorKdForest::IndexMatrix expected;
  forest.KnnSearch(queries, 3, 64, &expected);
  std::vector<DescriptorKdForest::IndexMatrix> results(2);
  std::vector<std::thread> threads;
  for (auto& result : results) {
    threads.emplace_back([&forest, &queries, &result] {
      for (int repeat = 0; repeat < 3; ++repeat) {
        forest.KnnSearch(queries, 3, 64, &result);
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (const auto& result : results) EXPECT_EQ(result, expected);
}

}  // namespace descriptor_kd_forest_test
}  // namespace rig_calibrator
