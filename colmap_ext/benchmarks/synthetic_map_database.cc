#include "colmap_ext/benchmarks/synthetic_map_database.h"

#include <colmap/base/database.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <random>
#include <sstream>
#include <unordered_set>

namespace rig_calibrator {
namespace {

// Map points fill the cube [-kSceneHalfSize, kSceneHalfSize]^3 (map units).
constexpr double kSceneHalfSize = 10.0;
// Rig cameras look at the origin from this distance.
constexpr double kRigCameraDistance = 40.0;
// Rig images see the points of the map images within this many ring steps of
// their "center" map image.
constexpr int kRigNeighbourhood = 3;

class DescriptorGenerator {
 public:
  explicit DescriptorGenerator(std::mt19937* random) : random_(random) {}

  // Half of the bins empty, the rest |N(0, 1)|, scaled to L2 norm 512.
  Eigen::VectorXf RandomBase() {
    Eigen::VectorXf base(128);
    for (int j = 0; j < 128; ++j) {
      base(j) = coin_(*random_) ? std::abs(normal_(*random_)) : 0.0f;
    }
    return base * (512.0f / std::max(base.norm(), 1e-6f));
  }

  // base + N(0, noise^2) per bin, clamped at 0, renormalized to 512, rounded
  // to uint8 as COLMAP stores SIFT descriptors.
  void Observe(const Eigen::VectorXf& base, double noise, uint8_t* row) {
    Eigen::VectorXf noisy = base;
    if (noise > 0) {
      for (int j = 0; j < 128; ++j) {
        noisy(j) = std::max(
            0.0f, noisy(j) + static_cast<float>(noise) * normal_(*random_));
      }
    }
    noisy *= 512.0f / std::max(noisy.norm(), 1e-6f);
    for (int j = 0; j < 128; ++j) {
      row[j] = static_cast<uint8_t>(std::min(255.0f, std::round(noisy(j))));
    }
  }

 private:
  std::mt19937* random_;
  std::normal_distribution<float> normal_;
  std::bernoulli_distribution coin_{0.5};
};

// One image's features before they are written: keypoint positions and the
// map point each observes (an index into the point bases, -1 for a
// distractor, whose descriptor is drawn when written).
struct ImageFeatures {
  colmap::FeatureKeypoints keypoints;
  std::vector<int> points;

  void Add(float x, float y, int point) {
    keypoints.emplace_back(x, y, 2.0f, 0.0f);
    points.push_back(point);
  }

  // Shuffles the features (a real extractor does not list the matchable ones
  // first) and writes keypoints and descriptors of `image_id`: observations
  // of the points' bases with `noise`, random descriptors for distractors.
  void Write(colmap::image_t image_id,
             const std::vector<Eigen::VectorXf>& bases, double noise,
             DescriptorGenerator* generator, std::mt19937* random,
             colmap::Database* database) {
    std::vector<int> order(keypoints.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
    std::shuffle(order.begin(), order.end(), *random);
    colmap::FeatureKeypoints shuffled_keypoints;
    std::vector<int> shuffled_points;
    colmap::FeatureDescriptors descriptors(order.size(), 128);
    for (size_t k = 0; k < order.size(); ++k) {
      const int point = points[order[k]];
      shuffled_keypoints.push_back(keypoints[order[k]]);
      shuffled_points.push_back(point);
      if (point >= 0) {
        generator->Observe(bases[point], noise, descriptors.row(k).data());
      } else {
        generator->Observe(generator->RandomBase(), 0,
                           descriptors.row(k).data());
      }
    }
    keypoints = std::move(shuffled_keypoints);
    points = std::move(shuffled_points);
    database->WriteKeypoints(image_id, keypoints);
    database->WriteDescriptors(image_id, descriptors);
  }
};

// cam_from_world of a camera at `center` looking at the origin, with the
// image's y axis pointing as much as possible towards -z (up in the image
// is +z in the world).
Rigid3d LookAtOrigin(const Eigen::Vector3d& center) {
  const Eigen::Vector3d forward = -center.normalized();
  const Eigen::Vector3d right =
      forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d cam_from_world_rotation;
  cam_from_world_rotation.row(0) = right;
  cam_from_world_rotation.row(1) = down;
  cam_from_world_rotation.row(2) = forward;
  return Rigid3d(cam_from_world_rotation, -cam_from_world_rotation * center);
}

std::string NumberedName(const std::string& prefix, int number) {
  std::ostringstream name;
  name << prefix << std::setw(6) << std::setfill('0') << number << ".png";
  return name.str();
}

// The random state shared by the steps, drawn in one fixed order so that a
// seed gives the same database.
struct Sampler {
  explicit Sampler(const SyntheticMapDatabaseOptions& options)
      : random(options.seed),
        generator(&random),
        pixel_x(0.5f, options.image_width - 0.5f),
        pixel_y(0.5f, options.image_height - 0.5f),
        map_image(0, options.num_map_images - 1) {}

  std::mt19937 random;
  DescriptorGenerator generator;
  std::uniform_real_distribution<float> pixel_x;
  std::uniform_real_distribution<float> pixel_y;
  std::uniform_int_distribution<int> map_image;
};

// The map points: a descriptor base, a position and a "home" map image, the
// first of the track_length consecutive map images that observe the point.
struct MapPoints {
  std::vector<Eigen::VectorXf> bases;
  std::vector<Eigen::Vector3d> xyzs;
  std::vector<int> home;
};

MapPoints DrawMapPoints(const SyntheticMapDatabaseOptions& options,
                        Sampler* sampler) {
  std::uniform_real_distribution<double> coordinate(-kSceneHalfSize,
                                                    kSceneHalfSize);
  const int num_points = options.num_map_images * options.points_per_map_image /
                         options.track_length;
  MapPoints points;
  points.bases.resize(num_points);
  points.xyzs.resize(num_points);
  points.home.resize(num_points);
  for (int p = 0; p < num_points; ++p) {
    points.bases[p] = sampler->generator.RandomBase();
    points.xyzs[p] = Eigen::Vector3d(coordinate(sampler->random),
                                     coordinate(sampler->random),
                                     coordinate(sampler->random));
    points.home[p] = sampler->map_image(sampler->random);
  }
  return points;
}

// The map images (identity poses; only the 2D-3D links matter) with their
// features in the database and in scene->map, then the map points with their
// tracks (ids 1..num_points in AddPoint3D order).
void WriteMapImages(const SyntheticMapDatabaseOptions& options,
                    const MapPoints& points, Sampler* sampler,
                    colmap::Database* database, SyntheticMapDatabase* scene) {
  colmap::Camera map_camera;
  map_camera.InitializeWithName("SIMPLE_RADIAL", 1.2 * options.image_width,
                                options.image_width, options.image_height);
  map_camera.SetCameraId(database->WriteCamera(map_camera));
  scene->map.AddCamera(map_camera);

  const int num_points = static_cast<int>(points.xyzs.size());
  std::vector<ImageFeatures> map_features(options.num_map_images);
  for (int p = 0; p < num_points; ++p) {
    for (int t = 0; t < options.track_length; ++t) {
      map_features[(points.home[p] + t) % options.num_map_images].Add(
          sampler->pixel_x(sampler->random), sampler->pixel_y(sampler->random),
          p);
    }
  }
  std::vector<colmap::Track> tracks(num_points);
  const int num_map_distractors =
      options.features_per_map_image - options.points_per_map_image;
  for (int i = 0; i < options.num_map_images; ++i) {
    ImageFeatures& features = map_features[i];
    for (int d = 0; d < num_map_distractors; ++d) {
      features.Add(sampler->pixel_x(sampler->random),
                   sampler->pixel_y(sampler->random), -1);
    }
    colmap::Image image;
    image.SetName(NumberedName("map/", 1000 + i));
    image.SetCameraId(map_camera.CameraId());
    const colmap::image_t image_id = database->WriteImage(image);
    features.Write(image_id, points.bases, options.descriptor_noise,
                   &sampler->generator, &sampler->random, database);
    scene->map_image_names.push_back(image.Name());

    image.SetImageId(image_id);
    std::vector<Eigen::Vector2d> points2D;
    for (size_t k = 0; k < features.keypoints.size(); ++k) {
      points2D.emplace_back(features.keypoints[k].x, features.keypoints[k].y);
      if (features.points[k] >= 0) {
        tracks[features.points[k]].AddElement(image_id, k);
      }
    }
    image.SetPoints2D(points2D);
    image.SetQvec(Eigen::Vector4d(1, 0, 0, 0));
    image.SetTvec(Eigen::Vector3d::Zero());
    scene->map.AddImage(image);
    scene->map.RegisterImage(image_id);
    features = ImageFeatures();
  }
  for (int p = 0; p < num_points; ++p) {
    scene->map.AddPoint3D(points.xyzs[p], tracks[p]);
  }
}

// A rig image's features: up to map_points_per_rig_image projections (with
// keypoint noise) of the points homed within kRigNeighbourhood map images of
// a random center image, then random distractors.
ImageFeatures RigImageFeatures(
    const SyntheticMapDatabaseOptions& options, const MapPoints& points,
    const std::vector<std::vector<int>>& points_of_image,
    const colmap::Camera& rig_camera, const Rigid3d& cam_from_world,
    std::normal_distribution<double>* keypoint_noise, Sampler* sampler) {
  const int center = sampler->map_image(sampler->random);
  std::vector<int> candidates;
  for (int offset = -kRigNeighbourhood; offset <= kRigNeighbourhood; ++offset) {
    const int i =
        ((center + offset) % options.num_map_images + options.num_map_images) %
        options.num_map_images;
    candidates.insert(candidates.end(), points_of_image[i].begin(),
                      points_of_image[i].end());
  }
  std::shuffle(candidates.begin(), candidates.end(), sampler->random);

  ImageFeatures features;
  // A small map wraps around the neighbourhood: candidates may repeat.
  std::unordered_set<int> used;
  for (const int p : candidates) {
    if (static_cast<int>(features.keypoints.size()) >=
        options.map_points_per_rig_image) {
      break;
    }
    if (!used.insert(p).second) continue;
    const Eigen::Vector3d point_cam = cam_from_world * points.xyzs[p];
    if (point_cam.z() <= 0) continue;
    const Eigen::Vector2d xy =
        rig_camera.WorldToImage(point_cam.hnormalized()) +
        Eigen::Vector2d((*keypoint_noise)(sampler->random),
                        (*keypoint_noise)(sampler->random));
    if (xy.x() < 0 || xy.y() < 0 || xy.x() > options.image_width ||
        xy.y() > options.image_height) {
      continue;
    }
    features.Add(static_cast<float>(xy.x()), static_cast<float>(xy.y()), p);
  }
  const int num_distractors =
      options.features_per_rig_image - features.keypoints.size();
  for (int d = 0; d < num_distractors; ++d) {
    features.Add(sampler->pixel_x(sampler->random),
                 sampler->pixel_y(sampler->random), -1);
  }
  return features;
}

// The rig images, round robin over the cameras, each looking at the origin
// from a random direction, with their true poses and planted matches in
// *scene.
void WriteRigImages(const SyntheticMapDatabaseOptions& options,
                    const MapPoints& points, Sampler* sampler,
                    colmap::Database* database, SyntheticMapDatabase* scene) {
  // Points by home map image, to pick the points a rig image sees.
  std::vector<std::vector<int>> points_of_image(options.num_map_images);
  for (size_t p = 0; p < points.home.size(); ++p) {
    points_of_image[points.home[p]].push_back(static_cast<int>(p));
  }
  colmap::Camera rig_camera;
  rig_camera.InitializeWithName("SIMPLE_PINHOLE", options.rig_focal_px,
                                options.image_width, options.image_height);
  std::vector<colmap::camera_t> rig_camera_ids;
  for (int c = 0; c < options.num_rig_cameras; ++c) {
    rig_camera_ids.push_back(database->WriteCamera(rig_camera));
  }
  std::uniform_real_distribution<double> angle(0, 2 * M_PI);
  std::uniform_real_distribution<double> elevation(-0.3, 0.3);
  std::normal_distribution<double> keypoint_noise(0, options.keypoint_noise_px);
  for (int r = 0; r < options.num_rig_images; ++r) {
    const double azimuth = angle(sampler->random);
    const double lift = elevation(sampler->random);
    const Rigid3d cam_from_world = LookAtOrigin(
        kRigCameraDistance * Eigen::Vector3d(std::cos(azimuth) * std::cos(lift),
                                             std::sin(azimuth) * std::cos(lift),
                                             std::sin(lift)));
    ImageFeatures features =
        RigImageFeatures(options, points, points_of_image, rig_camera,
                         cam_from_world, &keypoint_noise, sampler);
    const int camera = r % options.num_rig_cameras;
    colmap::Image image;
    image.SetName(NumberedName("cam" + std::to_string(camera) + "/",
                               10000 + r / options.num_rig_cameras));
    image.SetCameraId(rig_camera_ids[camera]);
    const colmap::image_t image_id = database->WriteImage(image);
    features.Write(image_id, points.bases, options.descriptor_noise,
                   &sampler->generator, &sampler->random, database);
    scene->rig_image_names.push_back(image.Name());
    scene->rig_cam_from_world.push_back(cam_from_world);
    // Map points have ids 1..num_points in AddPoint3D order.
    std::unordered_map<colmap::point2D_t, colmap::point3D_t> planted;
    for (size_t k = 0; k < features.points.size(); ++k) {
      if (features.points[k] >= 0) {
        planted[k] = static_cast<colmap::point3D_t>(features.points[k] + 1);
      }
    }
    scene->rig_planted.push_back(std::move(planted));
  }
}

}  // namespace

bool SyntheticMapDatabaseOptions::Check(std::string* error) const {
  std::ostringstream message;
  if (num_map_images < 1 || track_length < 1 || track_length > num_map_images) {
    message << "need num_map_images >= 1 and 1 <= track_length <= "
               "num_map_images, got "
            << num_map_images << " and " << track_length;
  } else if (points_per_map_image < 0 ||
             features_per_map_image < points_per_map_image) {
    message << "need 0 <= points_per_map_image <= features_per_map_image, got "
            << points_per_map_image << " and " << features_per_map_image;
  } else if (num_rig_images < 0 || num_rig_cameras < 1) {
    message << "need num_rig_images >= 0 and num_rig_cameras >= 1, got "
            << num_rig_images << " and " << num_rig_cameras;
  } else if (map_points_per_rig_image < 0 ||
             features_per_rig_image < map_points_per_rig_image) {
    message << "need 0 <= map_points_per_rig_image <= "
               "features_per_rig_image, got "
            << map_points_per_rig_image << " and " << features_per_rig_image;
  } else if (!(descriptor_noise >= 0) || !(keypoint_noise_px >= 0)) {
    message << "noises must be >= 0";
  } else if (image_width < 16 || image_height < 16 || !(rig_focal_px > 0)) {
    message << "need an image of at least 16 x 16 px and a positive focal";
  } else {
    return true;
  }
  *error = message.str();
  return false;
}

bool WriteSyntheticMapDatabase(const SyntheticMapDatabaseOptions& options,
                               const std::string& database_path,
                               SyntheticMapDatabase* scene,
                               std::string* error) {
  if (!options.Check(error)) return false;
  if (std::filesystem::exists(database_path)) {
    *error = database_path + " exists; the synthetic database needs a new file";
    return false;
  }
  *scene = SyntheticMapDatabase();
  Sampler sampler(options);
  const MapPoints points = DrawMapPoints(options, &sampler);
  colmap::Database database(database_path);
  colmap::DatabaseTransaction transaction(&database);
  WriteMapImages(options, points, &sampler, &database, scene);
  WriteRigImages(options, points, &sampler, &database, scene);
  return true;
}

}  // namespace rig_calibrator
