// The map localizer on a synthetic database with planted correspondences:
// direct index, retrieval (all images, direct votes, vocabulary tree) and
// verified database matches recover the planted ones; the database is never
// modified; missing images, features and unusable maps are reported.
#include "colmap_ext/localization/map_localizer.h"

#include <colmap/base/database.h>
#include <colmap/retrieval/visual_index.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <map>
#include <set>

#include "tests/colmap_ext/localization/localization_scene.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace map_localizer_test {

namespace fs = std::filesystem;

class MapLocalizerRetrievalTest : public testing::MapLocalizerTest {
 protected:
  // Retrieval finds the planted correspondences, matching each rig image to
  // no more than the retrieved map images.
  void ExpectRetrievalRecoversPlanted(const MapLocalizerOptions& options) {
    const std::vector<ImageLocalization> results = LocalizeAll(options);
    ExpectPlantedRecovered(results, CorrespondenceSource::kImageMatching);
    for (const ImageLocalization& result : results) {
      EXPECT_LE(result.num_map_images_matched, options.num_retrieved_images);
    }
  }
};

using testing::MapLocalizerTest;

TEST_F(MapLocalizerTest, DirectIndexRecoversPlantedCorrespondences) {
  MapLocalizerOptions options;
  options.num_threads = 2;
  ExpectPlantedRecovered(LocalizeAll(options),
                         CorrespondenceSource::kDirectIndex);
}

TEST_F(MapLocalizerTest, RetrievalOfAllMapImagesRecoversPlanted) {
  MapLocalizerOptions options;
  options.mode = LocalizationMode::kRetrieval;
  options.num_threads = 2;
  const std::vector<ImageLocalization> results = LocalizeAll(options);
  ExpectPlantedRecovered(results, CorrespondenceSource::kImageMatching);
  for (const ImageLocalization& result : results) {
    // Each planted point is seen by `track_length` map images.
    EXPECT_GE(result.num_candidates,
              2 * static_cast<int>(result.correspondences.size()));
  }
}

TEST_F(MapLocalizerRetrievalTest, ByDirectVotesRecoversPlanted) {
  MapLocalizerOptions options;
  options.mode = LocalizationMode::kRetrieval;
  options.max_num_map_images_exhaustive = 5;
  options.num_retrieved_images = 8;
  ExpectRetrievalRecoversPlanted(options);
}

TEST_F(MapLocalizerRetrievalTest, ByVocabularyTreeRecoversPlanted) {
  colmap::retrieval::VisualIndex<> tree;
  colmap::retrieval::VisualIndex<>::BuildOptions build_options;
  build_options.num_visual_words = 256;
  build_options.branching = 16;
  build_options.num_iterations = 5;
  build_options.num_threads = 2;
  tree.Build(build_options, scene_.all_map_descriptors);
  const std::string tree_path = temp_dir_.File("vocab_tree.bin");
  tree.Write(tree_path);

  MapLocalizerOptions options;
  options.mode = LocalizationMode::kRetrieval;
  options.vocab_tree_path = tree_path;
  options.num_retrieved_images = 8;
  ExpectRetrievalRecoversPlanted(options);
}

TEST_F(MapLocalizerTest, UsesVerifiedMatchesStoredInTheDatabase) {
  // Rig image 0 was matched by a COLMAP matcher: its planted keypoints have
  // inlier matches to the map images that see their points, plus two wrong
  // matches that the votes must overrule.
  const std::map<colmap::point2D_t, colmap::point3D_t>& planted =
      scene_.planted[0];
  ASSERT_GE(planted.size(), 2u);
  const colmap::point3D_t point_a = planted.begin()->second;
  const colmap::point2D_t keypoint_b = std::next(planted.begin())->first;
  const colmap::point3D_t point_b = std::next(planted.begin())->second;
  {
    reader_.Close();
    colmap::Database database(database_path_);
    std::map<colmap::image_t, colmap::FeatureMatches> matches;
    for (const auto& [keypoint, point3D_id] : planted) {
      for (const auto& [map_image_id, keypoint_of_point] :
           scene_.map_keypoint_of_point) {
        const auto it = keypoint_of_point.find(point3D_id);
        if (it != keypoint_of_point.end()) {
          matches[map_image_id].emplace_back(keypoint, it->second);
        }
      }
    }
    // Keypoint b also matched to point a in one image where b's own point is
    // not seen: a's 3 votes keep a, b keeps its own point.
    for (const auto& [map_image_id, keypoint_of_point] :
         scene_.map_keypoint_of_point) {
      if (keypoint_of_point.count(point_a) > 0 &&
          keypoint_of_point.count(point_b) == 0) {
        matches[map_image_id].emplace_back(keypoint_b,
                                           keypoint_of_point.at(point_a));
        break;
      }
    }
    for (const auto& [map_image_id, image_matches] : matches) {
      colmap::TwoViewGeometry geometry;
      geometry.config = colmap::TwoViewGeometry::UNCALIBRATED;
      geometry.inlier_matches = image_matches;
      database.WriteTwoViewGeometry(scene_.rig_image_ids[0], map_image_id,
                                    geometry);
    }
  }
  std::string error;
  ASSERT_TRUE(reader_.Open(database_path_, &error)) << error;

  MapLocalizerOptions options;
  std::vector<ImageLocalization> results = LocalizeAll(options);
  ASSERT_EQ(results.size(), scene_.rig_image_names.size());
  EXPECT_EQ(results[0].source, CorrespondenceSource::kDatabaseMatches);
  EXPECT_EQ(results[0].correspondences.size(), planted.size());
  EXPECT_EQ(results[0].num_candidates,
            static_cast<int>(config_.track_length * planted.size() + 1));
  for (size_t i = 0; i < results[0].correspondences.size(); ++i) {
    EXPECT_EQ(results[0].correspondences[i].point3D_id,
              static_cast<int64_t>(planted.at(results[0].point2D_idxs[i])));
  }
  for (size_t r = 1; r < results.size(); ++r) {
    EXPECT_EQ(results[r].source, CorrespondenceSource::kDirectIndex);
  }

  options.use_database_matches = false;
  results = LocalizeAll(options);
  EXPECT_EQ(results[0].source, CorrespondenceSource::kDirectIndex);
}

TEST_F(MapLocalizerTest, NeverModifiesTheDatabase) {
  reader_.Close();
  const std::string bytes_before = testing::ReadBytes(database_path_);
  const auto mtime_before = fs::last_write_time(database_path_);
  const std::set<std::string> files_before =
      testing::ListFolder(temp_dir_.path());
  std::string error;
  ASSERT_TRUE(reader_.Open(database_path_, &error)) << error;
  for (const LocalizationMode mode :
       {LocalizationMode::kDirect, LocalizationMode::kRetrieval}) {
    MapLocalizerOptions options;
    options.mode = mode;
    options.max_num_map_images_exhaustive = 0;
    options.num_retrieved_images = 3;
    EXPECT_EQ(LocalizeAll(options).size(), scene_.rig_image_names.size());
  }
  reader_.Close();
  EXPECT_EQ(testing::ReadBytes(database_path_), bytes_before);
  EXPECT_EQ(fs::last_write_time(database_path_), mtime_before);
  EXPECT_EQ(testing::ListFolder(temp_dir_.path()), files_before);
}

TEST_F(MapLocalizerTest, ReportsMissingRigImagesAndFeatures) {
  std::string error;
  std::unique_ptr<MapLocalizer> localizer =
      MapLocalizer::Create(MapLocalizerOptions(), scene_.map, &reader_, &error);
  ASSERT_NE(localizer, nullptr) << error;
  std::vector<ImageLocalization> results;
  EXPECT_FALSE(localizer->LocalizeImages(
      {scene_.rig_image_names[0], "cam0/0001.png"}, &results, &error));
  EXPECT_EQ(error, "the database " + database_path_ +
                       " has no image named cam0/0001.png: run colmap "
                       "feature_extractor on the rig images into this "
                       "database first (see README)");
  ImageLocalization result;
  EXPECT_FALSE(localizer->Localize("cam9/0001.png", &result, &error));
  EXPECT_NE(error.find("no image named cam9/0001.png"), std::string::npos);

  // An image whose descriptors were never written.
  reader_.Close();
  {
    colmap::Database database(database_path_);
    colmap::Image image;
    image.SetName("cam1/99999.png");
    image.SetCameraId(1);
    const colmap::image_t image_id = database.WriteImage(image);
    database.WriteKeypoints(image_id, colmap::FeatureKeypoints(3));
  }
  ASSERT_TRUE(reader_.Open(database_path_, &error)) << error;
  localizer =
      MapLocalizer::Create(MapLocalizerOptions(), scene_.map, &reader_, &error);
  ASSERT_NE(localizer, nullptr) << error;
  EXPECT_FALSE(localizer->Localize("cam1/99999.png", &result, &error));
  EXPECT_NE(error.find("has no descriptors for image cam1/99999.png"),
            std::string::npos)
      << error;
}

TEST_F(MapLocalizerTest, ReportsMapsItCannotUse) {
  std::string error;
  colmap::Reconstruction no_points;
  no_points.AddCamera(scene_.map.Camera(1));
  const colmap::Image& map_image =
      scene_.map.Image(scene_.map.RegImageIds()[0]);
  colmap::Image image;
  image.SetImageId(map_image.ImageId());
  image.SetName(map_image.Name());
  image.SetCameraId(map_image.CameraId());
  image.SetPoints2D(std::vector<Eigen::Vector2d>(map_image.NumPoints2D()));
  no_points.AddImage(image);
  no_points.RegisterImage(image.ImageId());
  EXPECT_EQ(
      MapLocalizer::Create(MapLocalizerOptions(), no_points, &reader_, &error),
      nullptr);
  EXPECT_NE(error.find("the map has no 3D points"), std::string::npos) << error;

  colmap::Reconstruction renamed = scene_.map;
  renamed.Image(renamed.RegImageIds()[0]).SetName("elsewhere/1.png");
  EXPECT_EQ(
      MapLocalizer::Create(MapLocalizerOptions(), renamed, &reader_, &error),
      nullptr);
  EXPECT_NE(error.find("map image elsewhere/1.png is not in the database"),
            std::string::npos)
      << error;

  MapLocalizerOptions options;
  options.mode = LocalizationMode::kRetrieval;
  options.vocab_tree_path = database_path_;  // not a vocabulary tree
  EXPECT_EQ(MapLocalizer::Create(options, scene_.map, &reader_, &error),
            nullptr);
  EXPECT_NE(error.find("not a COLMAP 3.8 vocabulary tree"), std::string::npos)
      << error;

  options.vocab_tree_path.clear();
  options.sift_matching.use_gpu = true;
  EXPECT_EQ(MapLocalizer::Create(options, scene_.map, &reader_, &error),
            nullptr);
  EXPECT_NE(error.find("use_gpu"), std::string::npos) << error;
}

// Every mode's name reads back as the mode.
TEST(LocalizationModeTest, NamesRoundTrip) {
  for (const LocalizationMode mode :
       {LocalizationMode::kDirect, LocalizationMode::kRetrieval}) {
    LocalizationMode read = mode == LocalizationMode::kDirect
                                ? LocalizationMode::kRetrieval
                                : LocalizationMode::kDirect;
    ASSERT_TRUE(LocalizationModeFromName(LocalizationModeName(mode), &read));
    EXPECT_EQ(read, mode);
  }
  EXPECT_EQ(LocalizationModeName(LocalizationMode::kDirect), "direct");
  EXPECT_EQ(LocalizationModeName(LocalizationMode::kRetrieval), "retrieval");
  LocalizationMode mode;
  EXPECT_FALSE(LocalizationModeFromName("exhaustive", &mode));
}

TEST(SelectOneToOneCorrespondencesTest, KeepsTheBestSupportedPairs) {
  // Keypoint 1 -> point 10 twice (2 votes) beats 1 -> 11; keypoint 2 -> 10
  // loses point 10 to keypoint 1 and keeps 12; keypoints 3 and 4 both want
  // point 13 with one vote: the smaller angle wins.
  const std::vector<CorrespondenceCandidate> candidates = {
      {1, 10, 1, 0.3f}, {1, 11, 1, 0.1f}, {2, 10, 1, 0.05f}, {1, 10, 1, 0.2f},
      {2, 12, 1, 0.4f}, {3, 13, 1, 0.3f}, {4, 13, 1, 0.25f}};
  std::vector<CorrespondenceCandidate> selected =
      SelectOneToOneCorrespondences(candidates);
  std::sort(selected.begin(), selected.end(), [](const auto& a, const auto& b) {
    return a.point2D_idx < b.point2D_idx;
  });
  ASSERT_EQ(selected.size(), 3u);
  EXPECT_EQ(selected[0].point2D_idx, 1u);
  EXPECT_EQ(selected[0].point3D_id, 10u);
  EXPECT_EQ(selected[0].votes, 2);
  EXPECT_FLOAT_EQ(selected[0].angle, 0.2f);
  EXPECT_EQ(selected[1].point2D_idx, 2u);
  EXPECT_EQ(selected[1].point3D_id, 12u);
  EXPECT_EQ(selected[2].point2D_idx, 4u);
  EXPECT_EQ(selected[2].point3D_id, 13u);
}

}  // namespace map_localizer_test
}  // namespace rig_calibrator
