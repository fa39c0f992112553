// MatchSiftDescriptors follows COLMAP's CPU matching rule: on two images that
// share noisy observations of the same features it returns COLMAP's matches
// (its exhaustive matcher as the reference), with and without the
// cross-check, and the same matches for the same seed.
#include "colmap_ext/localization/sift_pair_matching.h"

#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "tests/colmap_ext/colmap_testing.h"

namespace rig_calibrator {
namespace sift_pair_matching_test {

// Image 1: 300 features; image 2: observations of 200 of them (shuffled by
// reversing) and 100 features of its own.
std::pair<colmap::FeatureDescriptors, colmap::FeatureDescriptors> TwoImages() {
  testing::SiftLikeDescriptors generator(5);
  std::vector<Eigen::VectorXf> bases;
  for (int i = 0; i < 300; ++i) bases.push_back(generator.RandomBase());
  colmap::FeatureDescriptors image1(300, 128), image2(300, 128);
  for (int i = 0; i < 300; ++i) image1.row(i) = generator.Observe(bases[i], 10);
  for (int i = 0; i < 200; ++i) {
    image2.row(i) = generator.Observe(bases[199 - i], 10);
  }
  for (int i = 200; i < 300; ++i) {
    image2.row(i) = generator.Observe(generator.RandomBase(), 0);
  }
  return {image1, image2};
}

std::set<std::pair<int, int>> AsSet(const colmap::FeatureMatches& matches) {
  std::set<std::pair<int, int>> set;
  for (const colmap::FeatureMatch& match : matches) {
    set.emplace(match.point2D_idx1, match.point2D_idx2);
  }
  return set;
}

TEST(MatchSiftDescriptorsTest, FollowsColmapsRule) {
  const auto [image1, image2] = TwoImages();
  const DescriptorKdForest forest1(image1, kPairMatchingNumTrees, 0);
  const DescriptorKdForest forest2(image2, kPairMatchingNumTrees, 0);
  for (const bool cross_check : {true, false}) {
    SCOPED_TRACE(cross_check ? "cross-check" : "one way");
    colmap::SiftMatchingOptions options;
    options.cross_check = cross_check;
    colmap::FeatureMatches matches, again, reference;
    MatchSiftDescriptors(options, image1, forest1, image2, forest2, &matches);
    MatchSiftDescriptors(options, image1, forest1, image2, forest2, &again);
    colmap::MatchSiftFeaturesCPUBruteForce(options, image1, image2, &reference);
    EXPECT_EQ(AsSet(matches), AsSet(again));
    EXPECT_EQ(AsSet(matches), AsSet(reference));
    EXPECT_GT(matches.size(), 190u);
    for (const colmap::FeatureMatch& match : matches) {
      EXPECT_EQ(match.point2D_idx2, 199 - match.point2D_idx1);
    }
  }
}

TEST(MatchSiftDescriptorsTest, EmptyImageMatchesNothing) {
  const auto [image1, image2] = TwoImages();
  const colmap::FeatureDescriptors empty(0, 128);
  const DescriptorKdForest forest1(image1, kPairMatchingNumTrees, 0);
  const DescriptorKdForest empty_forest(empty, kPairMatchingNumTrees, 0);
  colmap::FeatureMatches matches;
  MatchSiftDescriptors(colmap::SiftMatchingOptions(), image1, forest1, empty,
                       empty_forest, &matches);
  EXPECT_TRUE(matches.empty());
  MatchSiftDescriptors(colmap::SiftMatchingOptions(), empty, empty_forest,
                       image1, forest1, &matches);
  EXPECT_TRUE(matches.empty());
}

}  // namespace sift_pair_matching_test
}  // namespace rig_calibrator
