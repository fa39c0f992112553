#include "colmap_ext/localization/map_localizer.h"

#include <colmap/base/database.h>
#include <colmap/feature/sift.h>
#include <colmap/retrieval/visual_index.h>
#include <colmap/util/bitmap.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <random>
#include <set>

#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace {

namespace fs = std::filesystem;

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

struct Feature {
  colmap::FeatureKeypoint keypoint;
  colmap::FeatureDescriptor descriptor;
  colmap::point3D_t point3D_id = colmap::kInvalidPoint3DId;
};

void WriteFeatures(colmap::Database* database, const colmap::image_t image_id,
                   const std::vector<Feature>& features) {
  colmap::FeatureKeypoints keypoints;
  colmap::FeatureDescriptors descriptors(features.size(), 128);
  for (size_t i = 0; i < features.size(); ++i) {
    keypoints.push_back(features[i].keypoint);
    descriptors.row(i) = features[i].descriptor;
  }
  database->WriteKeypoints(image_id, keypoints);
  database->WriteDescriptors(image_id, descriptors);
}

SyntheticScene MakeScene(const SceneConfig& config,
                         const std::string& database_path) {
  SyntheticScene scene;
  testing::SiftLikeDescriptors generator(config.seed);
  std::mt19937& random = generator.random();
  std::uniform_real_distribution<float> pixel_x(0.5f, 639.5f);
  std::uniform_real_distribution<float> pixel_y(0.5f, 479.5f);
  std::uniform_real_distribution<double> coordinate(-10, 10);
  const auto random_keypoint = [&]() {
    return colmap::FeatureKeypoint(pixel_x(random), pixel_y(random), 2.0f,
                                   0.0f);
  };

  std::vector<Eigen::VectorXf> bases(config.num_points);
  std::vector<Eigen::Vector3d> xyzs(config.num_points);
  std::vector<int> home(config.num_points);
  std::uniform_int_distribution<int> image_distribution(
      0, config.num_map_images - 1);
  for (int p = 0; p < config.num_points; ++p) {
    bases[p] = generator.RandomBase();
    xyzs[p] = Eigen::Vector3d(coordinate(random), coordinate(random),
                              coordinate(random));
    home[p] = image_distribution(random);
  }
  // Map points get ids 1..num_points in AddPoint3D order.
  const auto point3D_id_of = [](const int p) {
    return static_cast<colmap::point3D_t>(p + 1);
  };

  colmap::Database database(database_path);
  colmap::Camera map_camera;
  map_camera.InitializeWithName("SIMPLE_RADIAL", 500, 640, 480);
  map_camera.SetCameraId(database.WriteCamera(map_camera));
  scene.map.AddCamera(map_camera);

  // Map images: observations of their points and distractors, shuffled.
  std::vector<std::vector<Feature>> map_features(config.num_map_images);
  for (int p = 0; p < config.num_points; ++p) {
    for (int t = 0; t < config.track_length; ++t) {
      const int image = (home[p] + t) % config.num_map_images;
      map_features[image].push_back(
          {random_keypoint(),
           generator.Observe(bases[p], config.descriptor_noise),
           point3D_id_of(p)});
    }
  }
  std::vector<colmap::Track> tracks(config.num_points);
  size_t num_map_descriptors = 0;
  for (int i = 0; i < config.num_map_images; ++i) {
    for (int d = 0; d < config.map_distractors_per_image; ++d) {
      map_features[i].push_back({random_keypoint(),
                                 generator.Observe(generator.RandomBase(), 0),
                                 colmap::kInvalidPoint3DId});
    }
    std::shuffle(map_features[i].begin(), map_features[i].end(), random);
    num_map_descriptors += map_features[i].size();

    colmap::Image image;
    image.SetName("map/" + std::to_string(1000 + i) + ".png");
    image.SetCameraId(map_camera.CameraId());
    const colmap::image_t image_id = database.WriteImage(image);
    WriteFeatures(&database, image_id, map_features[i]);
    scene.map_image_ids.push_back(image_id);

    const colmap::image_t model_image_id =
        image_id + config.model_image_id_offset;
    image.SetImageId(model_image_id);
    std::vector<Eigen::Vector2d> points2D;
    for (size_t k = 0; k < map_features[i].size(); ++k) {
      const Feature& feature = map_features[i][k];
      points2D.emplace_back(feature.keypoint.x, feature.keypoint.y);
      if (feature.point3D_id != colmap::kInvalidPoint3DId) {
        tracks[feature.point3D_id - 1].AddElement(model_image_id, k);
        scene.map_keypoint_of_point[image_id][feature.point3D_id] = k;
      }
    }
    image.SetPoints2D(points2D);
    image.SetQvec(Eigen::Vector4d(1, 0, 0, 0));
    image.SetTvec(Eigen::Vector3d::Zero());
    scene.map.AddImage(image);
    scene.map.RegisterImage(model_image_id);
  }
  for (int p = 0; p < config.num_points; ++p) {
    EXPECT_EQ(scene.map.AddPoint3D(xyzs[p], tracks[p]), point3D_id_of(p));
  }
  scene.all_map_descriptors.resize(num_map_descriptors, 128);
  size_t row = 0;
  for (const std::vector<Feature>& features : map_features) {
    for (const Feature& feature : features) {
      scene.all_map_descriptors.row(row++) = feature.descriptor;
    }
  }

  // Rig images, one camera per folder: points of a few neighbouring map
  // images (as a rig image sees a part of the scene), and distractors.
  colmap::camera_t rig_camera_ids[2];
  for (int c = 0; c < 2; ++c) {
    colmap::Camera camera;
    camera.InitializeWithName("OPENCV_FISHEYE", 300, 640, 480);
    rig_camera_ids[c] = database.WriteCamera(camera);
  }
  for (int r = 0; r < config.num_rig_images; ++r) {
    const int center = (r * 7) % config.num_map_images;
    std::vector<int> visible;
    for (int p = 0; p < config.num_points; ++p) {
      const int offset =
          (home[p] - center + config.num_map_images) % config.num_map_images;
      if (offset <= 2 || offset >= config.num_map_images - 2) {
        visible.push_back(p);
      }
    }
    std::shuffle(visible.begin(), visible.end(), random);
    visible.resize(
        std::min<size_t>(visible.size(), config.planted_per_rig_image));
    std::vector<Feature> features;
    for (const int p : visible) {
      features.push_back({random_keypoint(),
                          generator.Observe(bases[p], config.descriptor_noise),
                          point3D_id_of(p)});
    }
    for (int d = 0; d < config.rig_distractors_per_image; ++d) {
      features.push_back({random_keypoint(),
                          generator.Observe(generator.RandomBase(), 0),
                          colmap::kInvalidPoint3DId});
    }
    std::shuffle(features.begin(), features.end(), random);

    colmap::Image image;
    const int camera = r % 2;
    image.SetName("cam" + std::to_string(camera) + "/" +
                  std::to_string(10000 + r / 2) + ".png");
    image.SetCameraId(rig_camera_ids[camera]);
    const colmap::image_t image_id = database.WriteImage(image);
    WriteFeatures(&database, image_id, features);
    scene.rig_image_names.push_back(image.Name());
    scene.rig_image_ids.push_back(image_id);
    std::map<colmap::point2D_t, colmap::point3D_t> planted;
    for (size_t k = 0; k < features.size(); ++k) {
      if (features[k].point3D_id != colmap::kInvalidPoint3DId) {
        planted[k] = features[k].point3D_id;
      }
    }
    scene.planted.push_back(planted);
  }
  return scene;
}

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
                         const std::vector<ImageLocalization>& results) {
  Score score;
  EXPECT_EQ(results.size(), scene.rig_image_names.size());
  for (size_t r = 0; r < results.size(); ++r) {
    const ImageLocalization& result = results[r];
    EXPECT_EQ(result.image_name, scene.rig_image_names[r]);
    EXPECT_EQ(result.correspondences.size(), result.point2D_idxs.size());
    EXPECT_GE(result.num_candidates,
              static_cast<int>(result.correspondences.size()));
    colmap::FeatureKeypoints keypoints;
    std::string error;
    EXPECT_TRUE(reader.ReadKeypoints(result.image_id, &keypoints, &error));
    std::set<colmap::point2D_t> seen_points2D;
    std::set<int64_t> seen_points3D;
    for (size_t i = 0; i < result.correspondences.size(); ++i) {
      const Correspondence& correspondence = result.correspondences[i];
      const colmap::point2D_t idx = result.point2D_idxs[i];
      EXPECT_TRUE(seen_points2D.insert(idx).second) << "keypoint used twice";
      EXPECT_TRUE(seen_points3D.insert(correspondence.point3D_id).second)
          << "map point used twice";
      EXPECT_EQ(correspondence.point2D.x(), keypoints.at(idx).x);
      EXPECT_EQ(correspondence.point2D.y(), keypoints.at(idx).y);
      EXPECT_EQ(correspondence.point3D,
                scene.map.Point3D(correspondence.point3D_id).XYZ());
      const auto planted = scene.planted[r].find(idx);
      if (planted != scene.planted[r].end() &&
          static_cast<int64_t>(planted->second) == correspondence.point3D_id) {
        ++score.num_correct;
      } else {
        ++score.num_wrong;
      }
    }
    score.num_planted += static_cast<int>(scene.planted[r].size());
  }
  return score;
}

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

TEST_F(MapLocalizerTest, RetrievalByDirectVotesRecoversPlanted) {
  MapLocalizerOptions options;
  options.mode = LocalizationMode::kRetrieval;
  options.max_num_map_images_exhaustive = 5;
  options.num_retrieved_images = 8;
  const std::vector<ImageLocalization> results = LocalizeAll(options);
  ExpectPlantedRecovered(results, CorrespondenceSource::kImageMatching);
  for (const ImageLocalization& result : results) {
    EXPECT_LE(result.num_map_images_matched, 8);
  }
}

TEST_F(MapLocalizerTest, RetrievalByVocabularyTreeRecoversPlanted) {
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
  const std::vector<ImageLocalization> results = LocalizeAll(options);
  ExpectPlantedRecovered(results, CorrespondenceSource::kImageMatching);
  for (const ImageLocalization& result : results) {
    EXPECT_LE(result.num_map_images_matched, 8);
  }
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

// A grey texture on the world plane z = 0 (x, y in [-1.5, 1.5]): random
// Gaussian blobs of several sizes, which SIFT detects at several scales.
class PlaneTexture {
 public:
  explicit PlaneTexture(const unsigned seed) : values_(kSize * kSize, 128) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> position(0, kSize);
    std::uniform_real_distribution<float> sigma(1.5f, 10.0f);
    std::uniform_real_distribution<float> amplitude(40, 120);
    std::bernoulli_distribution sign(0.5);
    for (int blob = 0; blob < 2500; ++blob) {
      const float cx = position(random);
      const float cy = position(random);
      const float s = sigma(random);
      const float a = sign(random) ? amplitude(random) : -amplitude(random);
      const int radius = static_cast<int>(std::ceil(3 * s));
      for (int y = std::max(0, static_cast<int>(cy) - radius);
           y < std::min(kSize, static_cast<int>(cy) + radius + 1); ++y) {
        for (int x = std::max(0, static_cast<int>(cx) - radius);
             x < std::min(kSize, static_cast<int>(cx) + radius + 1); ++x) {
          const float d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
          values_[y * kSize + x] += a * std::exp(-d2 / (2 * s * s));
        }
      }
    }
  }

  // Bilinear sample at world (x, y); mid grey outside the texture.
  float Sample(const double x, const double y) const {
    const double u = (x + 1.5) / 3.0 * kSize - 0.5;
    const double v = (y + 1.5) / 3.0 * kSize - 0.5;
    if (u < 0 || v < 0 || u >= kSize - 1 || v >= kSize - 1) return 128;
    const int u0 = static_cast<int>(u);
    const int v0 = static_cast<int>(v);
    const float fu = static_cast<float>(u - u0);
    const float fv = static_cast<float>(v - v0);
    const auto at = [this](int uu, int vv) { return values_[vv * kSize + uu]; };
    return (1 - fv) * ((1 - fu) * at(u0, v0) + fu * at(u0 + 1, v0)) +
           fv * ((1 - fu) * at(u0, v0 + 1) + fu * at(u0 + 1, v0 + 1));
  }

 private:
  static constexpr int kSize = 1024;
  std::vector<float> values_;
};

// Intersection of the ray of `pixel` with the plane z = 0.
Eigen::Vector3d BackProjectToPlane(const colmap::Camera& camera,
                                   const Rigid3d& cam_from_world,
                                   const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d normalized = camera.ImageToWorld(pixel);
  const Eigen::Vector3d direction =
      cam_from_world.RotationMatrix().transpose() *
      Eigen::Vector3d(normalized.x(), normalized.y(), 1);
  const Eigen::Vector3d center = cam_from_world.Center();
  return center - center.z() / direction.z() * direction;
}

colmap::Bitmap RenderView(const PlaneTexture& texture,
                          const colmap::Camera& camera,
                          const Rigid3d& cam_from_world) {
  colmap::Bitmap bitmap;
  bitmap.Allocate(camera.Width(), camera.Height(), /*as_rgb=*/false);
  for (size_t row = 0; row < camera.Height(); ++row) {
    for (size_t col = 0; col < camera.Width(); ++col) {
      // COLMAP pixel centers are at +0.5.
      const Eigen::Vector3d point = BackProjectToPlane(
          camera, cam_from_world, Eigen::Vector2d(col + 0.5, row + 0.5));
      const float value =
          std::clamp(texture.Sample(point.x(), point.y()), 0.0f, 255.0f);
      bitmap.SetPixel(col, row,
                      colmap::BitmapColor<uint8_t>(
                          static_cast<uint8_t>(std::lround(value))));
    }
  }
  return bitmap;
}

Rigid3d LookingAtPlane(const Eigen::Vector3d& center, const double yaw_deg,
                       const double roll_deg) {
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(roll_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()))
          .toRotationMatrix();
  return Rigid3d(rotation, -rotation * center);
}

// Real SIFT (COLMAP's CPU extractor) on two rendered views of a textured
// plane: the map is view A with one 3D point per keypoint (back-projected
// onto the plane), the rig image is view B; a correspondence is correct if
// its map point projects within 2 px of its keypoint in view B.
TEST(MapLocalizerRealSiftTest, LocalizesARenderedViewOfATexturedPlane) {
  const PlaneTexture texture(21);
  colmap::Camera camera;
  camera.InitializeWithName("PINHOLE", 500, 640, 480);
  camera.SetCameraId(1);
  const Rigid3d map_from_world =
      LookingAtPlane(Eigen::Vector3d(0, 0, -2), 0, 0);
  const Rigid3d rig_from_world =
      LookingAtPlane(Eigen::Vector3d(-0.3, 0.1, -1.8), 12, 8);

  colmap::SiftExtractionOptions extraction;
  extraction.use_gpu = false;
  extraction.num_threads = 1;
  colmap::FeatureKeypoints map_keypoints;
  colmap::FeatureKeypoints rig_keypoints;
  colmap::FeatureDescriptors map_descriptors;
  colmap::FeatureDescriptors rig_descriptors;
  ASSERT_TRUE(colmap::ExtractSiftFeaturesCPU(
      extraction, RenderView(texture, camera, map_from_world), &map_keypoints,
      &map_descriptors));
  ASSERT_TRUE(colmap::ExtractSiftFeaturesCPU(
      extraction, RenderView(texture, camera, rig_from_world), &rig_keypoints,
      &rig_descriptors));
  ASSERT_GT(map_keypoints.size(), 300u);
  ASSERT_GT(rig_keypoints.size(), 300u);

  testing::ScopedTempDir temp_dir;
  const std::string database_path = temp_dir.File("plane.db");
  colmap::Reconstruction map;
  {
    colmap::Database database(database_path);
    database.WriteCamera(camera, /*use_camera_id=*/true);
    colmap::Image image;
    image.SetName("map/a.png");
    image.SetCameraId(camera.CameraId());
    image.SetImageId(database.WriteImage(image));
    database.WriteKeypoints(image.ImageId(), map_keypoints);
    database.WriteDescriptors(image.ImageId(), map_descriptors);
    std::vector<Eigen::Vector2d> points2D;
    for (const colmap::FeatureKeypoint& keypoint : map_keypoints) {
      points2D.emplace_back(keypoint.x, keypoint.y);
    }
    image.SetPoints2D(points2D);
    image.SetQvec(map_from_world.Qvec());
    image.SetTvec(map_from_world.translation);
    map.AddCamera(camera);
    map.AddImage(image);
    map.RegisterImage(image.ImageId());
    for (colmap::point2D_t idx = 0; idx < points2D.size(); ++idx) {
      colmap::Track track;
      track.AddElement(image.ImageId(), idx);
      map.AddPoint3D(BackProjectToPlane(camera, map_from_world, points2D[idx]),
                     track);
    }
    colmap::Image rig_image;
    rig_image.SetName("cam0/0001.png");
    rig_image.SetCameraId(camera.CameraId());
    const colmap::image_t rig_image_id = database.WriteImage(rig_image);
    database.WriteKeypoints(rig_image_id, rig_keypoints);
    database.WriteDescriptors(rig_image_id, rig_descriptors);
  }
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(database_path, &error)) << error;

  for (const LocalizationMode mode :
       {LocalizationMode::kDirect, LocalizationMode::kRetrieval}) {
    MapLocalizerOptions options;
    options.mode = mode;
    std::unique_ptr<MapLocalizer> localizer =
        MapLocalizer::Create(options, map, &reader, &error);
    ASSERT_NE(localizer, nullptr) << error;
    ImageLocalization result;
    ASSERT_TRUE(localizer->Localize("cam0/0001.png", &result, &error)) << error;
    int num_correct = 0;
    for (const Correspondence& correspondence : result.correspondences) {
      const Eigen::Vector3d in_camera = rig_from_world * correspondence.point3D;
      const Eigen::Vector2d projection =
          camera.WorldToImage(in_camera.hnormalized());
      num_correct += (projection - correspondence.point2D).norm() < 2.0;
    }
    const int num_found = static_cast<int>(result.correspondences.size());
    std::cout << LocalizationModeName(mode) << ": " << map_keypoints.size()
              << " map / " << rig_keypoints.size() << " rig SIFT features, "
              << num_found << " correspondences, " << num_correct
              << " within 2 px" << std::endl;
    EXPECT_GT(num_found, 100);
    EXPECT_GE(num_correct, 0.95 * num_found);
  }
}

// Throughput on a map of 300 images x 2000 features (1200 with a 3D
// point), rig images of 2000 features (1000 of map points). Run with
// --gtest_also_run_disabled_tests; it prints a table and asserts nothing
// about time. CPU s/image (all threads) does not depend on the machine's
// load; images/s is wall time on 2 threads.
TEST(MapLocalizerBenchmark, DISABLED_Throughput) {
  SceneConfig config;
  config.num_map_images = 300;
  config.num_points = 300 * 1200 / 4;
  config.track_length = 4;
  config.map_distractors_per_image = 800;
  config.num_rig_images = 40;
  config.planted_per_rig_image = 1000;
  config.rig_distractors_per_image = 1000;
  testing::ScopedTempDir temp_dir;
  const std::string database_path = temp_dir.File("benchmark.db");
  SyntheticScene scene = MakeScene(config, database_path);
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(database_path, &error)) << error;

  struct Variant {
    LocalizationMode mode;
    int max_descriptors_per_point;
    int num_checks;
    int num_images;
  };
  // Image matching costs far more per image: time a few images only.
  const Variant variants[] = {{LocalizationMode::kDirect, 4, 128, 40},
                              {LocalizationMode::kDirect, 2, 128, 40},
                              {LocalizationMode::kDirect, 1, 128, 40},
                              {LocalizationMode::kDirect, 4, 64, 40},
                              {LocalizationMode::kDirect, 4, 32, 40},
                              {LocalizationMode::kRetrieval, 4, 128, 4}};
  for (const Variant& variant : variants) {
    MapLocalizerOptions options;
    options.mode = variant.mode;
    options.max_descriptors_per_point = variant.max_descriptors_per_point;
    options.index.num_checks = variant.num_checks;
    options.num_threads = 2;
    options.progress_interval = 0;
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<MapLocalizer> localizer =
        MapLocalizer::Create(options, scene.map, &reader, &error);
    ASSERT_NE(localizer, nullptr) << error;
    const double build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    const std::vector<std::string> names(
        scene.rig_image_names.begin(),
        scene.rig_image_names.begin() + variant.num_images);
    std::vector<ImageLocalization> results;
    const auto localize_start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    ASSERT_TRUE(localizer->LocalizeImages(names, &results, &error)) << error;
    const double cpu_seconds =
        static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                      localize_start)
            .count();
    int num_correct = 0;
    int num_returned = 0;
    int num_planted = 0;
    for (size_t r = 0; r < results.size(); ++r) {
      num_planted += scene.planted[r].size();
      for (size_t i = 0; i < results[r].correspondences.size(); ++i) {
        ++num_returned;
        const auto it = scene.planted[r].find(results[r].point2D_idxs[i]);
        num_correct += it != scene.planted[r].end() &&
                       static_cast<int64_t>(it->second) ==
                           results[r].correspondences[i].point3D_id;
      }
    }
    std::cout << LocalizationModeName(variant.mode) << " descriptors/point "
              << variant.max_descriptors_per_point << " checks "
              << variant.num_checks << ": "
              << localizer->NumIndexedDescriptors()
              << " indexed descriptors, ready in " << build_seconds << " s; "
              << names.size() << " images: " << cpu_seconds / names.size()
              << " CPU s/image, " << names.size() / seconds
              << " images/s (2 threads); recall "
              << static_cast<double>(num_correct) / num_planted
              << ", precision "
              << static_cast<double>(num_correct) / std::max(num_returned, 1)
              << std::endl;
  }
}

}  // namespace
}  // namespace rig_calibrator
