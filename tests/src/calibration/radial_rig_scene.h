// Synthetic rigs with known answers for the tests of the radial rig stages
// (rig initialization, radial bundle adjustment): per-image 1D radial poses,
// inlier masks and correspondences as the single-image localization would
// leave them, including mis-localized and unlocalized images and framesets
// that see only some of the cameras.
#pragma once

#include <colmap/base/camera.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "src/calibration/principal_axes.h"
#include "src/geometry/rigid3d.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {
namespace testing {

struct RadialRigSceneOptions {
  // false: 5 cameras on a ring, looking outward at 72 degree steps, centers
  // 0.12-0.18 m from the ring center, pitched and rolled by a few degrees.
  // true: two cameras 0.11 m apart along x, the first looking forward, the
  // second turned by pair_yaw_deg about the vertical axis: 0 a stereo pair
  // (parallel principal axes), 180 a front/back pair (anti-parallel).
  bool pair = false;
  double pair_yaw_deg = 0;
  int num_framesets = 30;
  int points_per_image = 60;
  // Gaussian noise on each pixel coordinate.
  double noise_px = 0;
  // Gaussian noise of the per-image radial poses: rotation about a random
  // axis through the centroid of the image's map points (degrees), then tx
  // and ty (map units).
  double pose_noise_deg = 0;
  double pose_noise_translation = 0;
  // Share of images mis-localized: a random pose, with correspondences (all
  // inliers) consistent with that wrong pose.
  double garbage_ratio = 0;
  // Share of images that were not localized (no pose, empty inlier mask).
  double missing_ratio = 0;
  // Images per frameset: that many cameras, picked at random.
  int min_cameras_per_frameset = 5;
  int max_cameras_per_frameset = 5;
  // Offset of the dataset cameras' principal points from the truth, pixels,
  // in a random direction per camera.
  double principal_point_error_px = 0;
  // The cameras: SIMPLE_RADIAL (pinhole + k1), 640 x 480, focal length
  // focal_length + 7 i px and k1 + 0.01 i for camera i.
  double focal_length = 420;
  double k1 = -0.12;
  unsigned int seed = 1;
};

struct RadialRigScene {
  RigDataset dataset;
  // cameras (true intrinsics), cam_from_rig (camera 0 = identity, true tz),
  // rig_from_world for every frameset, all cameras calibrated.
  RigCalibration truth;
  // What the single-image localization leaves: cameras = the dataset's,
  // images[k].single_image_cam_from_world (first two rows meaningful, tz
  // random) and inlier_mask.
  RigCalibration input;
  std::vector<char> garbage;  // per dataset image
};

inline Eigen::Quaterniond RandomRotation(std::mt19937* random) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(*random), normal(*random), normal(*random),
                            normal(*random))
      .normalized();
}

inline Eigen::Quaterniond RotationAbout(const Eigen::Vector3d& axis,
                                        double angle_deg) {
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis.normalized()));
}

// Correspondences of an image seen from cam_from_world: pixels drawn over
// the image, map points 2-10 map units in front of the camera.
inline std::vector<Correspondence> MakeCorrespondences(
    const colmap::Camera& camera, const Rigid3d& cam_from_world, int num_points,
    double noise_px, std::mt19937* random) {
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> noise(0, noise_px);
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  std::vector<Correspondence> correspondences;
  while (static_cast<int>(correspondences.size()) < num_points) {
    // Normalized coordinates: exact projection through the camera model.
    // Normalized coordinates, drawn over more than the field of view (barrel
    // distortion pulls them in) and kept if inside the image.
    const Eigen::Vector2d normalized(
        (2 * uniform(*random) - 1) * 0.65 * camera.Width() /
            camera.MeanFocalLength(),
        (2 * uniform(*random) - 1) * 0.65 * camera.Height() /
            camera.MeanFocalLength());
    const Eigen::Vector2d pixel = camera.WorldToImage(normalized);
    if (pixel.x() < 5 || pixel.y() < 5 || pixel.x() > camera.Width() - 5 ||
        pixel.y() > camera.Height() - 5) {
      continue;
    }
    const double depth = 2 + 8 * uniform(*random);
    Correspondence correspondence;
    correspondence.point3D =
        world_from_cam * (depth * normalized.homogeneous());
    correspondence.point2D =
        pixel + Eigen::Vector2d(noise(*random), noise(*random));
    correspondences.push_back(correspondence);
  }
  return correspondences;
}

// The cameras' poses in the rig body frame: x right, y down, z forward
// (camera-like); the ring's cameras turn about y.
inline std::vector<Rigid3d> CamFromBody(const RadialRigSceneOptions& options) {
  std::vector<Rigid3d> cam_from_body;
  if (options.pair) {
    cam_from_body.push_back(
        Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.055, 0, 0)));
    cam_from_body.push_back(
        Rigid3d(RotationAbout(Eigen::Vector3d::UnitY(), options.pair_yaw_deg),
                Eigen::Vector3d(0.055, 0, 0))
            .Inverse());
  } else {
    for (int i = 0; i < 5; ++i) {
      const double yaw = 72.0 * i;
      const Eigen::Quaterniond body_from_cam_rotation =
          RotationAbout(Eigen::Vector3d::UnitY(), yaw) *
          RotationAbout(Eigen::Vector3d::UnitX(), 4.0 * std::sin(1.7 * i)) *
          RotationAbout(Eigen::Vector3d::UnitZ(), 2.0 * std::cos(2.3 * i));
      const double radius = 0.15 + 0.03 * std::sin(2.9 * i);
      const Eigen::Vector3d center(radius * std::sin(yaw * M_PI / 180),
                                   0.02 * std::cos(1.3 * i),
                                   radius * std::cos(yaw * M_PI / 180));
      cam_from_body.push_back(
          Rigid3d(body_from_cam_rotation, center).Inverse());
    }
  }
  return cam_from_body;
}

// The scene's random numbers: one engine and one distribution of each kind,
// drawn in a fixed order (a normal distribution keeps state between draws).
struct SceneRandom {
  explicit SceneRandom(unsigned int seed) : engine(seed) {}
  double Uniform() { return uniform(engine); }
  double Normal() { return normal(engine); }
  std::mt19937 engine;
  std::uniform_real_distribution<double> uniform{0, 1};
  std::normal_distribution<double> normal;
};

// Camera i's image of frameset j, appended to the scene: correct (with the
// pose noise), mis-localized or not localized, as drawn.
inline void AddImage(const RadialRigSceneOptions& options, int i, int j,
                     SceneRandom* random, RadialRigScene* scene) {
  const Rigid3d true_cam_from_world =
      scene->truth.cam_from_rig[i] * *scene->truth.rig_from_world[j];
  RigImage image;
  image.name = "cam" + std::to_string(i) + "/" + std::to_string(j);
  image.camera_index = i;
  image.frameset_index = j;
  ImageResult result;
  const double kind = random->Uniform();
  const bool garbage = kind < options.garbage_ratio;
  const bool missing =
      !garbage && kind < options.garbage_ratio + options.missing_ratio;
  Rigid3d cam_from_world = true_cam_from_world;
  if (garbage) {
    cam_from_world =
        Rigid3d(RandomRotation(&random->engine),
                Eigen::Vector3d(3 * random->Normal(), 3 * random->Normal(), 0));
  }
  image.correspondences = MakeCorrespondences(
      scene->truth.cameras[i], cam_from_world, options.points_per_image,
      options.noise_px, &random->engine);
  if (!garbage) {
    // A single-image pose errs about the points it sees: the rotation
    // turns about their centroid, whose image stays put.
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Correspondence& correspondence : image.correspondences) {
      centroid += correspondence.point3D / image.correspondences.size();
    }
    const Eigen::Vector3d axis(random->Normal(), random->Normal(),
                               random->Normal());
    const Eigen::Vector3d centroid_in_cam = cam_from_world * centroid;
    cam_from_world.rotation =
        RotationAbout(axis, options.pose_noise_deg * random->Normal()) *
        cam_from_world.rotation;
    cam_from_world.translation =
        centroid_in_cam - cam_from_world.rotation * centroid;
    cam_from_world.translation.x() +=
        options.pose_noise_translation * random->Normal();
    cam_from_world.translation.y() +=
        options.pose_noise_translation * random->Normal();
  }
  if (!missing) {
    // The forward translation is unknown to a radial pose.
    cam_from_world.translation.z() = 10 * random->Normal();
    result.localized = true;
    result.single_image_cam_from_world = cam_from_world;
    result.inlier_mask.assign(image.correspondences.size(), 1);
    result.num_inliers = image.correspondences.size();
  }
  scene->dataset.images.push_back(image);
  scene->input.images.push_back(result);
  scene->garbage.push_back(garbage);
}

inline RadialRigScene MakeRadialRigScene(const RadialRigSceneOptions& options) {
  SceneRandom random(options.seed);
  RadialRigScene scene;
  RigDataset& dataset = scene.dataset;

  const std::vector<Rigid3d> cam_from_body = CamFromBody(options);
  const int num_cameras = cam_from_body.size();
  const Rigid3d body_from_rig = cam_from_body[0].Inverse();

  for (int i = 0; i < num_cameras; ++i) {
    colmap::Camera camera;
    camera.InitializeWithName("SIMPLE_RADIAL", options.focal_length + 7 * i,
                              640, 480);
    camera.SetPrincipalPointX(318.7 + 2.1 * i);
    camera.SetPrincipalPointY(242.3 - 1.7 * i);
    camera.Params(3) = options.k1 + 0.01 * i;
    scene.truth.cameras.push_back(camera);
    scene.truth.cam_from_rig.push_back(cam_from_body[i] * body_from_rig);
    scene.truth.camera_calibrated.push_back(true);

    RigCamera rig_camera;
    rig_camera.name = "cam" + std::to_string(i);
    rig_camera.camera = camera;
    const double direction = 2 * M_PI * random.Uniform();
    rig_camera.camera.SetPrincipalPointX(camera.PrincipalPointX() +
                                         options.principal_point_error_px *
                                             std::cos(direction));
    rig_camera.camera.SetPrincipalPointY(camera.PrincipalPointY() +
                                         options.principal_point_error_px *
                                             std::sin(direction));
    dataset.cameras.push_back(rig_camera);
    scene.input.cameras.push_back(rig_camera.camera);
  }
  scene.truth.cam_from_rig[0] = Rigid3d();

  for (int j = 0; j < options.num_framesets; ++j) {
    dataset.frameset_names.push_back(std::to_string(j));
    // A smooth path: turning, climbing a little, rocking.
    const Eigen::Quaterniond world_from_rig_rotation =
        RotationAbout(Eigen::Vector3d(0.1, 1, 0.2), 9.0 * j) *
        RotationAbout(Eigen::Vector3d::UnitX(), 5 * std::sin(0.7 * j));
    const Eigen::Vector3d rig_center(0.4 * j, 0.2 * std::sin(0.5 * j),
                                     2 * std::cos(0.15 * j));
    scene.truth.rig_from_world.push_back(
        Rigid3d(world_from_rig_rotation, rig_center).Inverse());

    std::vector<int> cameras(num_cameras);
    std::iota(cameras.begin(), cameras.end(), 0);
    std::shuffle(cameras.begin(), cameras.end(), random.engine);
    const int num_present =
        options.min_cameras_per_frameset +
        static_cast<int>(random.Uniform() *
                         (options.max_cameras_per_frameset -
                          options.min_cameras_per_frameset + 1));
    cameras.resize(std::min(num_present, num_cameras));
    std::sort(cameras.begin(), cameras.end());
    for (const int i : cameras) {
      AddImage(options, i, j, &random, &scene);
    }
  }
  return scene;
}

// The two-camera rig of RadialRigSceneOptions::pair, second camera turned by
// yaw_deg, every frameset with both cameras; a share of mis-localized images.
inline RadialRigScene MakePairScene(double yaw_deg, double garbage_ratio = 0) {
  RadialRigSceneOptions options;
  options.pair = true;
  options.pair_yaw_deg = yaw_deg;
  options.garbage_ratio = garbage_ratio;
  options.min_cameras_per_frameset = 2;
  options.max_cameras_per_frameset = 2;
  return MakeRadialRigScene(options);
}

// Frobenius norm of the difference of two rotations: sqrt(2) times the angle
// in radians for small angles, and accurate near zero, unlike acos.
inline double RotationDistance(const Rigid3d& a, const Rigid3d& b) {
  return (a.RotationMatrix() - b.RotationMatrix()).norm();
}

// The truth in the radial gauge of the estimates (NormalizeRadialRigOrigin
// about camera 0): its rotations and all radial projections are unchanged.
inline RigCalibration RadialTruth(const RadialRigScene& scene) {
  RigCalibration truth = scene.truth;
  NormalizeRadialRigOrigin(scene.dataset.reference_camera, &truth);
  return truth;
}

// Gives every localized image its true full pose (tz included): the input
// of the full-pose (rd_ra, known*) rig initialization on exact data.
inline void UseTrueFullPoses(RadialRigScene* scene) {
  for (size_t k = 0; k < scene->dataset.images.size(); ++k) {
    const RigImage& image = scene->dataset.images[k];
    std::optional<Rigid3d>& pose =
        scene->input.images[k].single_image_cam_from_world;
    if (pose) {
      pose =
          scene->truth.CamFromWorld(image.camera_index, image.frameset_index);
    }
  }
}

// Every camera calibrated and every rig pose set, each within `tolerance`
// of the truth: rotations in RotationDistance, translations in norm.
inline void ExpectRigNear(const RigCalibration& estimate,
                          const RigCalibration& truth, double tolerance) {
  ASSERT_EQ(estimate.cam_from_rig.size(), truth.cam_from_rig.size());
  ASSERT_EQ(estimate.rig_from_world.size(), truth.rig_from_world.size());
  for (size_t i = 0; i < truth.cam_from_rig.size(); ++i) {
    SCOPED_TRACE("camera " + std::to_string(i));
    ASSERT_TRUE(estimate.camera_calibrated[i]);
    EXPECT_LT(RotationDistance(estimate.cam_from_rig[i], truth.cam_from_rig[i]),
              tolerance);
    EXPECT_LT((estimate.cam_from_rig[i].translation -
               truth.cam_from_rig[i].translation)
                  .norm(),
              tolerance);
  }
  for (size_t j = 0; j < truth.rig_from_world.size(); ++j) {
    SCOPED_TRACE("frameset " + std::to_string(j));
    ASSERT_TRUE(estimate.rig_from_world[j]);
    EXPECT_LT(
        RotationDistance(*estimate.rig_from_world[j], *truth.rig_from_world[j]),
        tolerance);
    EXPECT_LT((estimate.rig_from_world[j]->translation -
               truth.rig_from_world[j]->translation)
                  .norm(),
              tolerance);
  }
}

}  // namespace testing
}  // namespace rig_calibrator
