// The synthetic scene of the map localizer tests: a COLMAP database with map
// and rig images whose rig keypoints are planted observations of map points,
// the matching map, a score of localizations against the planted truth and
// the test fixture that localizes all rig images.
#pragma once

#include <colmap/base/reconstruction.h>
#include <colmap/feature/types.h>
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/map_localizer.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace testing {

struct SceneConfig {
  int num_map_images = 12;
  int num_points = 1000;
  // Point p is seen by map images home(p), home(p) + 1, ... (a ring), so
  // neighbouring map images share points as along a real trajectory.
  int track_length = 3;
  int map_distractors_per_image = 100;  // keypoints without a 3D point
  int num_rig_images = 4;
  int planted_per_rig_image = 150;  // keypoints of map points
  int rig_distractors_per_image = 100;
  // Per-dimension descriptor noise (descriptors have L2 norm 512), about
  // 0.25 rad between two observations of a point.
  double descriptor_noise = 10;
  // Model image ids differ from database ids (names link them).
  colmap::image_t model_image_id_offset = 100;
  unsigned seed = 7;
};

// A COLMAP database with map and rig images (random SIFT-like descriptors:
// every observation of a map point is its descriptor plus noise) and the
// matching map (colmap::Reconstruction), with the planted rig keypoint ->
// map point assignment.
struct SyntheticScene {
  colmap::Reconstruction map;
  std::vector<std::string> rig_image_names;
  // Per rig image: keypoint index -> map point3D id.
  std::vector<std::map<colmap::point2D_t, colmap::point3D_t>> planted;
  // Per map image (database id): map point3D id -> keypoint index.
  std::map<colmap::image_t, std::map<colmap::point3D_t, colmap::point2D_t>>
      map_keypoint_of_point;
  std::vector<colmap::image_t> map_image_ids;  // database ids
  std::vector<colmap::image_t> rig_image_ids;  // database ids
  colmap::FeatureDescriptors all_map_descriptors;
};

// Writes the scene's database at database_path (a new file).
SyntheticScene MakeScene(const SceneConfig& config,
                         const std::string& database_path);

struct Score {
  int num_correct = 0;
  int num_wrong = 0;
  int num_planted = 0;
};

// Checks that every correspondence is consistent with the database and the
// map and that no keypoint and no map point appears twice; counts the
// correspondences that agree with the planted ones.
Score ScoreLocalizations(const SyntheticScene& scene,
                         const DatabaseReader& reader,
                         const std::vector<ImageLocalization>& results);

class MapLocalizerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    database_path_ = temp_dir_.File("scene.db");
    scene_ = MakeScene(config_, database_path_);
    std::string error;
    ASSERT_TRUE(reader_.Open(database_path_, &error)) << error;
  }

  std::vector<ImageLocalization> LocalizeAll(
      const MapLocalizerOptions& options) {
    std::string error;
    std::unique_ptr<MapLocalizer> localizer =
        MapLocalizer::Create(options, scene_.map, &reader_, &error);
    EXPECT_NE(localizer, nullptr) << error;
    std::vector<ImageLocalization> results;
    if (localizer != nullptr) {
      EXPECT_EQ(localizer->NumMapImages(),
                static_cast<size_t>(config_.num_map_images));
      EXPECT_EQ(localizer->NumMapPoints(),
                static_cast<size_t>(config_.num_points));
      EXPECT_TRUE(
          localizer->LocalizeImages(scene_.rig_image_names, &results, &error))
          << error;
    }
    return results;
  }

  void ExpectPlantedRecovered(const std::vector<ImageLocalization>& results,
                              const CorrespondenceSource expected_source) {
    for (const ImageLocalization& result : results) {
      EXPECT_EQ(result.source, expected_source)
          << CorrespondenceSourceName(result.source);
    }
    const Score score = ScoreLocalizations(scene_, reader_, results);
    EXPECT_GT(score.num_correct, 0.95 * score.num_planted)
        << score.num_correct << " of " << score.num_planted;
    EXPECT_LE(score.num_wrong, 0.01 * score.num_planted) << score.num_wrong;
  }

  SceneConfig config_;
  testing::ScopedTempDir temp_dir_;
  std::string database_path_;
  SyntheticScene scene_;
  DatabaseReader reader_;
};

}  // namespace testing
}  // namespace rig_calibrator
