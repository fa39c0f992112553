// Direct localization with guidance (strongest features first, then matching
// along radial lines once the 1D radial pose is certain) against the same
// localization without it, on a geometrically consistent synthetic map
// (WriteSyntheticMapDatabase): the same images localize, as many planted
// correspondences are found, none of them wrong, and the result is the same
// on 1 and 2 threads. RadialLineIndex's geometric rule on a hand-made scene.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "colmap_ext/benchmarks/synthetic_map_database.h"
#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/map_localizer.h"
#include "colmap_ext/localization/radial_guided_matching.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace map_localizer_guidance_test {

struct Counts {
  long correct = 0;
  long wrong = 0;
  long guided = 0;
  int images_with_correspondences = 0;
};

class MapLocalizerGuidanceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    SyntheticMapDatabaseOptions options;
    options.num_map_images = 40;
    options.features_per_map_image = 400;
    options.points_per_map_image = 300;
    options.num_rig_images = 6;
    options.features_per_rig_image = 1500;
    options.map_points_per_rig_image = 700;
    options.seed = 3;
    std::string error;
    ASSERT_TRUE(WriteSyntheticMapDatabase(options, temp_dir_.File("map.db"),
                                          &scene_, &error))
        << error;
    ASSERT_TRUE(reader_.Open(temp_dir_.File("map.db"), &error)) << error;
  }

  std::vector<ImageLocalization> Localize(MapLocalizerOptions options) {
    options.progress_interval = 0;
    std::string error;
    const std::unique_ptr<MapLocalizer> localizer =
        MapLocalizer::Create(options, scene_.map, &reader_, &error);
    EXPECT_NE(localizer, nullptr) << error;
    std::vector<ImageLocalization> results;
    if (localizer == nullptr) return results;
    EXPECT_TRUE(
        localizer->LocalizeImages(scene_.rig_image_names, &results, &error))
        << error;
    return results;
  }

  Counts Count(const std::vector<ImageLocalization>& results) const {
    Counts counts;
    for (size_t r = 0; r < results.size(); ++r) {
      counts.guided += results[r].num_guided_queries;
      counts.images_with_correspondences +=
          results[r].correspondences.empty() ? 0 : 1;
      for (size_t i = 0; i < results[r].correspondences.size(); ++i) {
        const auto planted =
            scene_.rig_planted[r].find(results[r].point2D_idxs[i]);
        const bool correct = planted != scene_.rig_planted[r].end() &&
                             static_cast<int64_t>(planted->second) ==
                                 results[r].correspondences[i].point3D_id;
        (correct ? counts.correct : counts.wrong) += 1;
      }
    }
    return counts;
  }

  testing::ScopedTempDir temp_dir_;
  SyntheticMapDatabase scene_;
  DatabaseReader reader_;
};

TEST_F(MapLocalizerGuidanceTest, FindsWhatTheFullSearchFinds) {
  MapLocalizerOptions unguided;
  unguided.guidance.enabled = false;
  const Counts full = Count(Localize(unguided));
  MapLocalizerOptions guided_options;
  guided_options.guidance.enabled = true;
  const Counts guided = Count(Localize(guided_options));
  std::cout << "full search: " << full.correct << " correct, " << full.wrong
            << " wrong; guided: " << guided.correct << " correct, "
            << guided.wrong << " wrong, " << guided.guided
            << " features matched along radial lines\n";
  EXPECT_EQ(guided.images_with_correspondences,
            full.images_with_correspondences);
  EXPECT_EQ(guided.images_with_correspondences, 6);
  EXPECT_GT(guided.guided, 0);  // the poses became certain
  EXPECT_GE(guided.correct, full.correct * 99 / 100);
  EXPECT_LE(guided.wrong, full.wrong + guided.correct / 100);
}

TEST_F(MapLocalizerGuidanceTest, NeverCertainIsTheFullSearch) {
  MapLocalizerOptions unguided;
  unguided.guidance.enabled = false;
  MapLocalizerOptions never_certain;
  never_certain.guidance.enabled = true;
  never_certain.guidance.min_pose_inliers = 100000;
  const std::vector<ImageLocalization> a = Localize(unguided);
  const std::vector<ImageLocalization> b = Localize(never_certain);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].point2D_idxs, b[i].point2D_idxs);
    EXPECT_EQ(b[i].num_guided_queries, 0);
  }
}

TEST_F(MapLocalizerGuidanceTest, SameOnOneAndTwoThreads) {
  MapLocalizerOptions options;
  options.guidance.enabled = true;
  options.index.num_checks = 8;  // approximate: depends on the forest
  options.num_threads = 1;
  const std::vector<ImageLocalization> one = Localize(options);
  options.num_threads = 2;
  const std::vector<ImageLocalization> two = Localize(options);
  ASSERT_EQ(one.size(), two.size());
  for (size_t i = 0; i < one.size(); ++i) {
    EXPECT_GT(one[i].num_guided_queries, 0);
    EXPECT_EQ(one[i].point2D_idxs, two[i].point2D_idxs);
    ASSERT_EQ(one[i].correspondences.size(), two[i].correspondences.size());
    for (size_t c = 0; c < one[i].correspondences.size(); ++c) {
      EXPECT_EQ(one[i].correspondences[c].point3D_id,
                two[i].correspondences[c].point3D_id);
    }
  }
}

// Map points on the world x axis at x = 1, 2 and on the y axis at y = 1;
// identity pose, so the radial projection of (x, y, z) is (x, y).
TEST(RadialLineIndexTest, MatchesPointsNearTheRadialLineOnItsSide) {
  LocalizationMap map;
  map.points[1].xyz = Eigen::Vector3d(1, 0, 5);
  map.points[2].xyz = Eigen::Vector3d(0, 1, 5);
  colmap::FeatureDescriptors point_descriptors(2, 128);
  point_descriptors.setZero();
  // Norm ~512 as COLMAP's: point 1 in bins 0-3, point 2 in bins 4-7.
  point_descriptors.block(0, 0, 1, 4).setConstant(255);
  point_descriptors.block(1, 4, 1, 4).setConstant(255);
  PointDescriptorIndex index;
  index.SetDescriptors(point_descriptors, {1, 2});
  const RadialLineIndex lines(map, index, {1, 2, 3}, Rigid3d());
  EXPECT_EQ(lines.NumPoints(), 2u);  // point 3 is not in the map

  // Features with point 1's descriptor at: on its line (+x), 5 px off it,
  // 10 px off it, on the opposite side (-x), near the center.
  colmap::FeatureDescriptors query(5, 128);
  query.setZero();
  query.leftCols(4).setConstant(255);
  const std::vector<Eigen::Vector2d> points2D = {
      {100, 0}, {100, 5}, {100, 10}, {-100, 0}, {3, 0}};
  RadialGuidedMatchingOptions options;
  options.max_line_distance_px = 8;
  std::vector<PointDescriptorIndex::PointMatch> matches;
  lines.Match(query, points2D, {0, 1, 2, 3, 4}, options, &matches);
  ASSERT_EQ(matches.size(), 2u);
  EXPECT_EQ(matches[0].query_idx, 0u);
  EXPECT_EQ(matches[1].query_idx, 1u);
  for (const auto& match : matches) {
    EXPECT_EQ(match.point3D_id, 1u);
    // The norm is 510, not 512.
    EXPECT_NEAR(match.angle, std::acos(4 * 255.0 * 255.0 / (512.0 * 512.0)),
                1e-6);
  }

  // A window across +-pi: point 4 at direction ~pi.
  map.points[4].xyz = Eigen::Vector3d(-1, -1e-3, 5);
  index.SetDescriptors(point_descriptors, {4, 2});
  const RadialLineIndex wrapped(map, index, {4, 2}, Rigid3d());
  matches.clear();
  lines.Match(query, {{-100, 0.5}}, {0}, options, &matches);
  EXPECT_TRUE(matches.empty());  // the first index has no point at -x
  wrapped.Match(query, {{-100, 0.5}}, {0}, options, &matches);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].point3D_id, 4u);
}

}  // namespace map_localizer_guidance_test
}  // namespace rig_calibrator
