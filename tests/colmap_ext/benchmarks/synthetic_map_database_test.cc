#include "colmap_ext/benchmarks/synthetic_map_database.h"

#include <gtest/gtest.h>

#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/map_localizer.h"
#include "src/estimators/radial_pose_estimator.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace synthetic_map_database_test {

SyntheticMapDatabaseOptions SmallOptions() {
  SyntheticMapDatabaseOptions options;
  options.num_map_images = 20;
  options.features_per_map_image = 300;
  options.points_per_map_image = 200;
  options.num_rig_images = 4;
  options.features_per_rig_image = 300;
  options.map_points_per_rig_image = 150;
  options.seed = 3;
  return options;
}

// A database written from SmallOptions into scene.db.
class SyntheticMapDatabaseTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(WriteSyntheticMapDatabase(options_, temp_dir_.File("scene.db"),
                                          &scene_, &error_))
        << error_;
  }

  testing::ScopedTempDir temp_dir_;
  const SyntheticMapDatabaseOptions options_ = SmallOptions();
  SyntheticMapDatabase scene_;
  std::string error_;
};

// The database holds what the options say, the map's tracks point at
// keypoints of the database images, and the planted rig keypoints are the
// projections of their map points.
TEST_F(SyntheticMapDatabaseTest, DatabaseMatchesMapAndRigGeometry) {
  EXPECT_EQ(scene_.map.NumRegImages(), 20u);
  EXPECT_EQ(scene_.map.NumPoints3D(), 20u * 200 / 4);
  ASSERT_EQ(scene_.rig_image_names.size(), 4u);
  EXPECT_EQ(scene_.rig_image_names[1], "cam1/010000.png");

  DatabaseReader reader;
  ASSERT_TRUE(reader.Open(temp_dir_.File("scene.db"), &error_)) << error_;
  EXPECT_EQ(reader.Images().size(), 24u);
  for (const colmap::image_t image_id : scene_.map.RegImageIds()) {
    const colmap::Image& image = scene_.map.Image(image_id);
    const DatabaseImage* database_image =
        reader.FindImageWithName(image.Name());
    ASSERT_NE(database_image, nullptr) << image.Name();
    EXPECT_EQ(database_image->image_id, image_id);
    EXPECT_EQ(reader.NumKeypoints(image_id),
              static_cast<int>(image.NumPoints2D()));
    EXPECT_EQ(reader.NumDescriptors(image_id),
              static_cast<int>(image.NumPoints2D()));
  }

  colmap::Camera rig_camera;
  rig_camera.InitializeWithName("SIMPLE_PINHOLE", options_.rig_focal_px,
                                options_.image_width, options_.image_height);
  for (size_t r = 0; r < scene_.rig_image_names.size(); ++r) {
    const DatabaseImage* image =
        reader.FindImageWithName(scene_.rig_image_names[r]);
    ASSERT_NE(image, nullptr);
    colmap::FeatureKeypoints keypoints;
    ASSERT_TRUE(reader.ReadKeypoints(image->image_id, &keypoints, &error_));
    EXPECT_EQ(keypoints.size(), 300u);
    EXPECT_GE(scene_.rig_planted[r].size(), 120u);
    EXPECT_LE(scene_.rig_planted[r].size(), 150u);
    for (const auto& [point2D_idx, point3D_id] : scene_.rig_planted[r]) {
      const Eigen::Vector3d point_cam =
          scene_.rig_cam_from_world[r] * scene_.map.Point3D(point3D_id).XYZ();
      const Eigen::Vector2d projection =
          rig_camera.WorldToImage(point_cam.hnormalized());
      EXPECT_LT((projection - Eigen::Vector2d(keypoints[point2D_idx].x,
                                              keypoints[point2D_idx].y))
                    .norm(),
                0.5 * 6)  // 6 sigma of the keypoint noise
          << point2D_idx;
    }
  }

  EXPECT_FALSE(WriteSyntheticMapDatabase(options_, temp_dir_.File("scene.db"),
                                         &scene_, &error_));
  EXPECT_NE(error_.find("exists"), std::string::npos);
  SyntheticMapDatabaseOptions bad = options_;
  bad.map_points_per_rig_image = 400;
  EXPECT_FALSE(WriteSyntheticMapDatabase(bad, temp_dir_.File("bad.db"), &scene_,
                                         &error_));
  EXPECT_NE(error_.find("map_points_per_rig_image"), std::string::npos);
}

// The localizer finds the planted correspondences, and the radial pose
// estimated from them is the true one.
TEST_F(SyntheticMapDatabaseTest,
       LocalizerRecoversPlantedCorrespondencesAndPose) {
  DatabaseReader reader;
  ASSERT_TRUE(reader.Open(temp_dir_.File("scene.db"), &error_)) << error_;
  MapLocalizerOptions localizer_options;
  localizer_options.num_threads = 1;
  localizer_options.progress_interval = 0;
  const std::unique_ptr<MapLocalizer> localizer =
      MapLocalizer::Create(localizer_options, scene_.map, &reader, &error_);
  ASSERT_NE(localizer, nullptr) << error_;
  std::vector<ImageLocalization> results;
  ASSERT_TRUE(
      localizer->LocalizeImages(scene_.rig_image_names, &results, &error_))
      << error_;
  ASSERT_EQ(results.size(), 4u);
  for (size_t r = 0; r < results.size(); ++r) {
    int num_correct = 0;
    for (size_t i = 0; i < results[r].correspondences.size(); ++i) {
      const auto planted =
          scene_.rig_planted[r].find(results[r].point2D_idxs[i]);
      num_correct += planted != scene_.rig_planted[r].end() &&
                     static_cast<int64_t>(planted->second) ==
                         results[r].correspondences[i].point3D_id;
    }
    EXPECT_GE(num_correct, 0.9 * scene_.rig_planted[r].size()) << r;
    EXPECT_GE(num_correct, 0.95 * results[r].correspondences.size()) << r;

    std::vector<Eigen::Vector2d> points2D;
    std::vector<Eigen::Vector3d> points3D;
    for (const Correspondence& correspondence : results[r].correspondences) {
      points2D.push_back(correspondence.point2D -
                         Eigen::Vector2d(0.5 * options_.image_width,
                                         0.5 * options_.image_height));
      points3D.push_back(correspondence.point3D);
    }
    RadialPoseEstimate estimate;
    ASSERT_TRUE(EstimateRadialPose(RadialPoseEstimationOptions(), points2D,
                                   points3D, &estimate));
    EXPECT_LT(RotationDifferenceDeg(estimate.cam_from_world.rotation,
                                    scene_.rig_cam_from_world[r].rotation),
              0.5)
        << r;
  }
}

}  // namespace synthetic_map_database_test
}  // namespace rig_calibrator
