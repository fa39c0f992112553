#include "tests/colmap_ext/localization/localization_scene.h"

#include <colmap/base/database.h>

#include <algorithm>
#include <random>
#include <set>

#include "tests/colmap_ext/colmap_testing.h"

namespace rig_calibrator {
namespace testing {
namespace {

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

colmap::FeatureKeypoint RandomKeypoint(std::mt19937* random) {
  std::uniform_real_distribution<float> pixel_x(0.5f, 639.5f);
  std::uniform_real_distribution<float> pixel_y(0.5f, 479.5f);
  return colmap::FeatureKeypoint(pixel_x(*random), pixel_y(*random), 2.0f,
                                 0.0f);
}

// Map point p: descriptor base, position and home map image; its id is
// p + 1 (AddPoint3D order).
struct ScenePoints {
  std::vector<Eigen::VectorXf> bases;
  std::vector<Eigen::Vector3d> xyzs;
  std::vector<int> home;
};

colmap::point3D_t Point3DIdOf(const int p) {
  return static_cast<colmap::point3D_t>(p + 1);
}

ScenePoints DrawScenePoints(const SceneConfig& config,
                            SiftLikeDescriptors* generator) {
  std::mt19937& random = generator->random();
  std::uniform_real_distribution<double> coordinate(-10, 10);
  std::uniform_int_distribution<int> image_distribution(
      0, config.num_map_images - 1);
  ScenePoints points;
  points.bases.resize(config.num_points);
  points.xyzs.resize(config.num_points);
  points.home.resize(config.num_points);
  for (int p = 0; p < config.num_points; ++p) {
    points.bases[p] = generator->RandomBase();
    points.xyzs[p] = Eigen::Vector3d(coordinate(random), coordinate(random),
                                     coordinate(random));
    points.home[p] = image_distribution(random);
  }
  return points;
}

// Map images: observations of their points and distractors, shuffled; model
// image ids are the database ids + model_image_id_offset.
void WriteMapImages(const SceneConfig& config, const ScenePoints& points,
                    SiftLikeDescriptors* generator, colmap::Database* database,
                    SyntheticScene* scene) {
  std::mt19937& random = generator->random();
  colmap::Camera map_camera;
  map_camera.InitializeWithName("SIMPLE_RADIAL", 500, 640, 480);
  map_camera.SetCameraId(database->WriteCamera(map_camera));
  scene->map.AddCamera(map_camera);

  std::vector<std::vector<Feature>> map_features(config.num_map_images);
  for (int p = 0; p < config.num_points; ++p) {
    for (int t = 0; t < config.track_length; ++t) {
      const int image = (points.home[p] + t) % config.num_map_images;
      map_features[image].push_back(
          {RandomKeypoint(&random),
           generator->Observe(points.bases[p], config.descriptor_noise),
           Point3DIdOf(p)});
    }
  }
  std::vector<colmap::Track> tracks(config.num_points);
  size_t num_map_descriptors = 0;
  for (int i = 0; i < config.num_map_images; ++i) {
    for (int d = 0; d < config.map_distractors_per_image; ++d) {
      map_features[i].push_back({RandomKeypoint(&random),
                                 generator->Observe(generator->RandomBase(), 0),
                                 colmap::kInvalidPoint3DId});
    }
    std::shuffle(map_features[i].begin(), map_features[i].end(), random);
    num_map_descriptors += map_features[i].size();

    colmap::Image image;
    image.SetName("map/" + std::to_string(1000 + i) + ".png");
    image.SetCameraId(map_camera.CameraId());
    const colmap::image_t image_id = database->WriteImage(image);
    WriteFeatures(database, image_id, map_features[i]);
    scene->map_image_ids.push_back(image_id);

    const colmap::image_t model_image_id =
        image_id + config.model_image_id_offset;
    image.SetImageId(model_image_id);
    std::vector<Eigen::Vector2d> points2D;
    for (size_t k = 0; k < map_features[i].size(); ++k) {
      const Feature& feature = map_features[i][k];
      points2D.emplace_back(feature.keypoint.x, feature.keypoint.y);
      if (feature.point3D_id != colmap::kInvalidPoint3DId) {
        tracks[feature.point3D_id - 1].AddElement(model_image_id, k);
        scene->map_keypoint_of_point[image_id][feature.point3D_id] = k;
      }
    }
    image.SetPoints2D(points2D);
    image.SetQvec(Eigen::Vector4d(1, 0, 0, 0));
    image.SetTvec(Eigen::Vector3d::Zero());
    scene->map.AddImage(image);
    scene->map.RegisterImage(model_image_id);
  }
  for (int p = 0; p < config.num_points; ++p) {
    EXPECT_EQ(scene->map.AddPoint3D(points.xyzs[p], tracks[p]), Point3DIdOf(p));
  }
  scene->all_map_descriptors.resize(num_map_descriptors, 128);
  size_t row = 0;
  for (const std::vector<Feature>& features : map_features) {
    for (const Feature& feature : features) {
      scene->all_map_descriptors.row(row++) = feature.descriptor;
    }
  }
}

// Rig images, one camera per folder: points of a few neighbouring map
// images (as a rig image sees a part of the scene), and distractors.
void WriteRigImages(const SceneConfig& config, const ScenePoints& points,
                    SiftLikeDescriptors* generator, colmap::Database* database,
                    SyntheticScene* scene) {
  std::mt19937& random = generator->random();
  colmap::camera_t rig_camera_ids[2];
  for (int c = 0; c < 2; ++c) {
    colmap::Camera camera;
    camera.InitializeWithName("OPENCV_FISHEYE", 300, 640, 480);
    rig_camera_ids[c] = database->WriteCamera(camera);
  }
  for (int r = 0; r < config.num_rig_images; ++r) {
    const int center = (r * 7) % config.num_map_images;
    std::vector<int> visible;
    for (int p = 0; p < config.num_points; ++p) {
      const int offset = (points.home[p] - center + config.num_map_images) %
                         config.num_map_images;
      if (offset <= 2 || offset >= config.num_map_images - 2) {
        visible.push_back(p);
      }
    }
    std::shuffle(visible.begin(), visible.end(), random);
    visible.resize(
        std::min<size_t>(visible.size(), config.planted_per_rig_image));
    std::vector<Feature> features;
    for (const int p : visible) {
      features.push_back(
          {RandomKeypoint(&random),
           generator->Observe(points.bases[p], config.descriptor_noise),
           Point3DIdOf(p)});
    }
    for (int d = 0; d < config.rig_distractors_per_image; ++d) {
      features.push_back({RandomKeypoint(&random),
                          generator->Observe(generator->RandomBase(), 0),
                          colmap::kInvalidPoint3DId});
    }
    std::shuffle(features.begin(), features.end(), random);

    colmap::Image image;
    const int camera = r % 2;
    image.SetName("cam" + std::to_string(camera) + "/" +
                  std::to_string(10000 + r / 2) + ".png");
    image.SetCameraId(rig_camera_ids[camera]);
    const colmap::image_t image_id = database->WriteImage(image);
    WriteFeatures(database, image_id, features);
    scene->rig_image_names.push_back(image.Name());
    scene->rig_image_ids.push_back(image_id);
    std::map<colmap::point2D_t, colmap::point3D_t> planted;
    for (size_t k = 0; k < features.size(); ++k) {
      if (features[k].point3D_id != colmap::kInvalidPoint3DId) {
        planted[k] = features[k].point3D_id;
      }
    }
    scene->planted.push_back(planted);
  }
}

}  // namespace

SyntheticScene MakeScene(const SceneConfig& config,
                         const std::string& database_path) {
  SyntheticScene scene;
  SiftLikeDescriptors generator(config.seed);
  const ScenePoints points = DrawScenePoints(config, &generator);
  colmap::Database database(database_path);
  WriteMapImages(config, points, &generator, &database, &scene);
  WriteRigImages(config, points, &generator, &database, &scene);
  return scene;
}

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

}  // namespace testing
}  // namespace rig_calibrator
