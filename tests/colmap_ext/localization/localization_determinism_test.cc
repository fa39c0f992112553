// Same input, same result: the FLANN forest is the same for the same seed, and
// the map localizer gives the same correspondences on 1 and 2 threads (each
// run builds its own index, as separate runs of the command do). The searches
// use few leaf checks, so that the approximate neighbours depend on the trees:
// the forest tests show that another seed then changes them, i.e. that an
// unseeded build (FLANN's own, from std::random_device) would fail here.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "colmap_ext/localization/descriptor_kd_forest.h"
#include "colmap_ext/localization/map_localizer.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/colmap_ext/localization/localization_scene.h"

namespace rig_calibrator {
namespace localization_determinism_test {

colmap::FeatureDescriptors RandomDescriptors(const int num_rows,
                                             const unsigned int seed) {
  testing::SiftLikeDescriptors generator(seed);
  colmap::FeatureDescriptors descriptors(num_rows, 128);
  for (int row = 0; row < num_rows; ++row) {
    descriptors.row(row) = generator.Observe(generator.RandomBase(), 0);
  }
  return descriptors;
}

// Rows of a and b that differ.
int NumDifferentRows(const DescriptorKdForest::IndexMatrix& a,
                     const DescriptorKdForest::IndexMatrix& b) {
  int num_different = 0;
  for (int row = 0; row < a.rows(); ++row) {
    num_different += a.row(row) == b.row(row) ? 0 : 1;
  }
  return num_different;
}

TEST(DescriptorKdForestTest, SameSeedGivesTheSameNeighbours) {
  const colmap::FeatureDescriptors data = RandomDescriptors(5000, 1);
  const colmap::FeatureDescriptors query = RandomDescriptors(500, 2);
  constexpr int kNumNeighbours = 3;
  constexpr int kNumChecks = 8;  // approximate: the result depends on the trees
  DescriptorKdForest::IndexMatrix first, second, other_seed;
  DescriptorKdForest(data, 4, 0)
      .KnnSearch(query, kNumNeighbours, kNumChecks, &first);
  DescriptorKdForest(data, 4, 0)
      .KnnSearch(query, kNumNeighbours, kNumChecks, &second);
  DescriptorKdForest(data, 4, 1)
      .KnnSearch(query, kNumNeighbours, kNumChecks, &other_seed);
  ASSERT_EQ(first.rows(), 500);
  ASSERT_EQ(first.cols(), kNumNeighbours);
  EXPECT_EQ(NumDifferentRows(first, second), 0);
  const int num_changed = NumDifferentRows(first, other_seed);
  std::cout << "queries whose 3 approximate neighbours change with the seed: "
            << num_changed << " of 500\n";
  EXPECT_GT(num_changed, 50);
  for (int row = 0; row < first.rows(); ++row) {
    for (int n = 0; n < kNumNeighbours; ++n) {
      EXPECT_GE(first(row, n), 0);
      EXPECT_LT(first(row, n), data.rows());
    }
  }
}

void ExpectSameLocalizations(const std::vector<ImageLocalization>& a,
                             const std::vector<ImageLocalization>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE(a[i].image_name);
    EXPECT_EQ(a[i].image_name, b[i].image_name);
    EXPECT_EQ(a[i].source, b[i].source);
    EXPECT_EQ(a[i].num_candidates, b[i].num_candidates);
    EXPECT_EQ(a[i].num_map_images_matched, b[i].num_map_images_matched);
    EXPECT_EQ(a[i].point2D_idxs, b[i].point2D_idxs);
    ASSERT_EQ(a[i].correspondences.size(), b[i].correspondences.size());
    for (size_t k = 0; k < a[i].correspondences.size(); ++k) {
      const Correspondence& x = a[i].correspondences[k];
      const Correspondence& y = b[i].correspondences[k];
      EXPECT_EQ(x.point3D_id, y.point3D_id);
      // Exact: the same keypoints and map points, copied, not computed.
      EXPECT_EQ(x.point2D, y.point2D);
      EXPECT_EQ(x.point3D, y.point3D);
    }
  }
}

size_t NumCorrespondences(const std::vector<ImageLocalization>& results) {
  size_t num = 0;
  for (const ImageLocalization& result : results) {
    num += result.correspondences.size();
  }
  return num;
}

class LocalizationDeterminismTest : public testing::MapLocalizerTest {
 protected:
  // Localizes on 1, then 2 threads and expects identical results.
  std::vector<ImageLocalization> ExpectSameOnOneAndTwoThreads(
      MapLocalizerOptions options) {
    options.num_threads = 1;
    const std::vector<ImageLocalization> one = LocalizeAll(options);
    options.num_threads = 2;
    const std::vector<ImageLocalization> two = LocalizeAll(options);
    ExpectSameLocalizations(one, two);
    EXPECT_GT(NumCorrespondences(one), 0u);
    return one;
  }
};

MapLocalizerOptions FewChecks() {
  MapLocalizerOptions options;
  options.index.num_checks = 4;
  options.progress_interval = 0;
  return options;
}

TEST_F(LocalizationDeterminismTest, DirectIndexOnOneAndTwoThreads) {
  MapLocalizerOptions options = FewChecks();
  const std::vector<ImageLocalization> seed0 =
      ExpectSameOnOneAndTwoThreads(options);
  // The comparison can see another forest: another seed changes the result.
  options.index.seed = 1;
  const std::vector<ImageLocalization> seed1 = LocalizeAll(options);
  int num_images_changed = 0;
  for (size_t i = 0; i < seed0.size(); ++i) {
    num_images_changed +=
        seed0[i].point2D_idxs == seed1[i].point2D_idxs ? 0 : 1;
  }
  std::cout << "direct index, 4 checks: " << NumCorrespondences(seed0)
            << " correspondences with seed 0, " << NumCorrespondences(seed1)
            << " with seed 1; " << num_images_changed << " of " << seed0.size()
            << " images changed\n";
  EXPECT_GT(num_images_changed, 0);
}

TEST_F(LocalizationDeterminismTest, RetrievalOfAllMapImagesOnOneAndTwoThreads) {
  MapLocalizerOptions options = FewChecks();
  options.mode = LocalizationMode::kRetrieval;
  ExpectSameOnOneAndTwoThreads(options);
}

TEST_F(LocalizationDeterminismTest, RetrievalByDirectVotesOnOneAndTwoThreads) {
  MapLocalizerOptions options = FewChecks();
  options.mode = LocalizationMode::kRetrieval;
  options.max_num_map_images_exhaustive = 5;
  options.num_retrieved_images = 4;
  ExpectSameOnOneAndTwoThreads(options);
}

}  // namespace localization_determinism_test
}  // namespace rig_calibrator
