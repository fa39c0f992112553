// The synthetic scenes of the final bundle adjustment's tests
// (final_bundle_adjuster_test.cc, final_bundle_adjuster_map_points_test.cc):
// a fixture shared on purpose by both.
#pragma once

#include <colmap/base/camera_models.h>
#include <colmap/util/math.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "src/calibration/final_bundle_adjuster.h"

namespace rig_calibrator {
namespace final_ba_testing {

struct SceneOptions {
  int model_id = colmap::OpenCVCameraModel::kModelId;
  int num_cameras = 4;
  int num_framesets = 20;
  int num_points_per_image = 100;
  double noise_px = 0;
  double outlier_ratio = 0;
  // true: images observe one world point cloud (shared point ids); false:
  // every observation has its own point (id -1), spread over the image.
  bool shared_points = false;
  unsigned seed = 1;
};

// A synthetic rig looking around (camera i turned by i * 360 / num_cameras
// degrees about the rig's y axis), walked through a scene with points 2-10 m
// away; some images are missing.
struct SyntheticBaScene {
  RigDataset dataset;
  RigCalibration truth;
  // Per image, per correspondence: replaced by a random pixel.
  std::vector<std::vector<char>> is_gross_outlier;
};

inline Eigen::Quaterniond RotationAboutAxis(double angle_rad,
                                            const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis.normalized()));
}

inline colmap::Camera MakeCamera(int model_id, int index) {
  colmap::Camera camera;
  camera.SetModelId(model_id);
  if (model_id == colmap::OpenCVFisheyeCameraModel::kModelId) {
    // f * 75 deg * (1 + distortion) reaches the image border: 150 deg FOV.
    camera.SetWidth(640);
    camera.SetHeight(640);
    camera.SetParams({250.0 + 5 * index, 251.0 + 5 * index, 320.0 + 3 * index,
                      320.0 - 2 * index, 0.05, -0.01, 0.002, -0.0005});
  } else {
    // k2 keeps r (1 + k1 r^2 + k2 r^4) monotonic over the whole image.
    camera.SetWidth(640);
    camera.SetHeight(480);
    camera.SetParams({500.0 + 10 * index, 501.0 + 10 * index, 320.0 + 3 * index,
                      240.0 - 2 * index, -0.3, 0.08, 1e-4, -2e-4});
  }
  return camera;
}

// Half of the field of view kept for observations.
inline double MaxViewAngleRad(int model_id) {
  return colmap::DegToRad(
      model_id == colmap::OpenCVFisheyeCameraModel::kModelId ? 75.0 : 50.0);
}

inline bool InImage(const colmap::Camera& camera, const Eigen::Vector2d& x) {
  return x.x() >= 0 && x.y() >= 0 && x.x() <= camera.Width() &&
         x.y() <= camera.Height();
}

inline SyntheticBaScene MakeSyntheticRig(const SceneOptions& options) {
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> gaussian(0, 1);
  const auto random_unit = [&]() {
    return Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng))
        .normalized();
  };

  SyntheticBaScene rig;
  RigDataset& dataset = rig.dataset;
  RigCalibration& truth = rig.truth;
  for (int i = 0; i < options.num_cameras; ++i) {
    RigCamera camera;
    camera.name = "cam" + std::to_string(i);
    camera.camera = MakeCamera(options.model_id, i);
    dataset.cameras.push_back(camera);
    truth.cameras.push_back(camera.camera);
    truth.camera_calibrated.push_back(true);
    // Camera i looks along yaw_i with a small tilt, 15 cm from the rig
    // center; camera 0 defines the rig frame.
    const double yaw = 2 * M_PI * i / options.num_cameras;
    const Eigen::Quaterniond rig_from_cam =
        RotationAboutAxis(yaw, Eigen::Vector3d::UnitY()) *
        RotationAboutAxis(i == 0 ? 0 : colmap::DegToRad(3.0 * i),
                          Eigen::Vector3d::UnitX());
    const Eigen::Vector3d center_in_rig =
        i == 0 ? Eigen::Vector3d::Zero()
               : Eigen::Vector3d(0.15 * std::sin(yaw), 0.02 * i,
                                 0.15 * (std::cos(yaw) - 1));
    truth.cam_from_rig.push_back(
        Rigid3d(rig_from_cam, center_in_rig).Inverse());
  }

  std::vector<Eigen::Vector3d> cloud;
  if (options.shared_points) {
    for (int p = 0; p < 3000; ++p) {
      cloud.push_back(random_unit() * (4 + 6 * uniform(rng)));
    }
  }

  for (int j = 0; j < options.num_framesets; ++j) {
    dataset.frameset_names.push_back("frame" + std::to_string(j));
    const double a = 2 * M_PI * j / options.num_framesets;
    const Eigen::Vector3d rig_center(std::cos(a), 0.2 * std::sin(3 * a),
                                     std::sin(a));
    const Eigen::Quaterniond world_from_rig =
        RotationAboutAxis(0.7 * a, Eigen::Vector3d::UnitY()) *
        RotationAboutAxis(colmap::DegToRad(5 * uniform(rng)), random_unit());
    truth.rig_from_world.push_back(
        Rigid3d(world_from_rig, rig_center).Inverse());
    for (int i = 0; i < options.num_cameras; ++i) {
      if ((j * options.num_cameras + i) % 7 == 3) {
        continue;  // a missing image
      }
      RigImage image;
      image.name = dataset.cameras[i].name + "/" + dataset.frameset_names[j];
      image.camera_index = i;
      image.frameset_index = j;
      const colmap::Camera& camera = truth.cameras[i];
      const Rigid3d cam_from_world = truth.CamFromWorld(i, j);
      const Rigid3d world_from_cam = cam_from_world.Inverse();
      const auto observe = [&](const Eigen::Vector3d& point_in_cam,
                               Eigen::Vector2d* x) {
        if (std::atan2(point_in_cam.head<2>().norm(), point_in_cam.z()) >
            MaxViewAngleRad(options.model_id)) {
          return false;
        }
        *x = camera.WorldToImage(point_in_cam.hnormalized());
        return InImage(camera, *x);
      };
      if (options.shared_points) {
        std::vector<int> order(cloud.size());
        for (size_t p = 0; p < order.size(); ++p) order[p] = p;
        std::shuffle(order.begin(), order.end(), rng);
        for (int p : order) {
          Correspondence correspondence;
          if (observe(cam_from_world * cloud[p], &correspondence.point2D)) {
            correspondence.point3D = cloud[p];
            correspondence.point3D_id = p;
            image.correspondences.push_back(correspondence);
          }
          if (static_cast<int>(image.correspondences.size()) ==
              options.num_points_per_image) {
            break;
          }
        }
      } else {
        while (static_cast<int>(image.correspondences.size()) <
               options.num_points_per_image) {
          const Eigen::Vector2d pixel(uniform(rng) * camera.Width(),
                                      uniform(rng) * camera.Height());
          const Eigen::Vector3d point_in_cam =
              camera.ImageToWorld(pixel).homogeneous().normalized() *
              (2 + 8 * uniform(rng));
          Correspondence correspondence;
          if (point_in_cam.z() > 0 &&
              observe(point_in_cam, &correspondence.point2D)) {
            correspondence.point3D = world_from_cam * point_in_cam;
            image.correspondences.push_back(correspondence);
          }
        }
      }
      std::vector<char> is_outlier(image.correspondences.size(), 0);
      for (size_t k = 0; k < image.correspondences.size(); ++k) {
        Eigen::Vector2d& x = image.correspondences[k].point2D;
        x += options.noise_px * Eigen::Vector2d(gaussian(rng), gaussian(rng));
        if (uniform(rng) < options.outlier_ratio) {
          x = Eigen::Vector2d(uniform(rng) * camera.Width(),
                              uniform(rng) * camera.Height());
          is_outlier[k] = 1;
        }
      }
      ImageResult result;
      result.localized = true;
      result.inlier_mask.assign(image.correspondences.size(), 1);
      truth.images.push_back(result);
      rig.is_gross_outlier.push_back(is_outlier);
      dataset.images.push_back(image);
    }
  }
  return rig;
}

inline Rigid3d Perturb(const Rigid3d& pose, double angle_deg, double distance,
                       std::mt19937* rng) {
  std::normal_distribution<double> gaussian(0, 1);
  const Eigen::Vector3d axis(gaussian(*rng), gaussian(*rng), gaussian(*rng));
  const Eigen::Vector3d direction(gaussian(*rng), gaussian(*rng),
                                  gaussian(*rng));
  return Rigid3d(
      RotationAboutAxis(colmap::DegToRad(angle_deg), axis) * pose.rotation,
      pose.translation + distance * direction.normalized());
}

// The start of the adjustment: rotations off by 1 deg, translations by 2 cm,
// focal lengths by 2 %, principal points by 10 px, k1 by 0.02.
inline RigCalibration PerturbedStart(const SyntheticBaScene& rig, unsigned seed) {
  std::mt19937 rng(seed);
  RigCalibration start = rig.truth;
  for (size_t i = 0; i < start.cameras.size(); ++i) {
    if (static_cast<int>(i) != rig.dataset.reference_camera) {
      start.cam_from_rig[i] = Perturb(start.cam_from_rig[i], 1, 0.02, &rng);
    }
    std::vector<double>& params = start.cameras[i].Params();
    const double sign = i % 2 == 0 ? 1 : -1;
    params[0] *= 1 + 0.02 * sign;
    params[1] *= 1 + 0.02 * sign;
    params[2] += 10 * sign;
    params[3] -= 10;
    params[4] += 0.02 * sign;
  }
  for (std::optional<Rigid3d>& pose : start.rig_from_world) {
    pose = Perturb(*pose, 1, 0.02, &rng);
  }
  return start;
}

// Largest errors of an estimate against the truth.
struct CalibrationErrors {
  double rotation_deg = 0;  // cam_from_rig and rig_from_world
  double center = 0;        // camera centers in the rig, rig centers
  double focal_relative = 0;
  double principal_point_px = 0;
  double k1 = 0;
};

inline CalibrationErrors Compare(const RigCalibration& estimate,
                                 const RigCalibration& truth) {
  CalibrationErrors errors;
  const auto add_pose = [&](const Rigid3d& a, const Rigid3d& b) {
    errors.rotation_deg = std::max(
        errors.rotation_deg, RotationDifferenceDeg(a.rotation, b.rotation));
    errors.center = std::max(errors.center, (a.Center() - b.Center()).norm());
  };
  for (size_t i = 0; i < truth.cameras.size(); ++i) {
    add_pose(estimate.cam_from_rig[i], truth.cam_from_rig[i]);
    const std::vector<double>& p = estimate.cameras[i].Params();
    const std::vector<double>& q = truth.cameras[i].Params();
    for (int k : {0, 1}) {
      errors.focal_relative =
          std::max(errors.focal_relative, std::abs(p[k] / q[k] - 1));
    }
    for (int k : {2, 3}) {
      errors.principal_point_px =
          std::max(errors.principal_point_px, std::abs(p[k] - q[k]));
    }
    errors.k1 = std::max(errors.k1, std::abs(p[4] - q[4]));
  }
  for (size_t j = 0; j < truth.rig_from_world.size(); ++j) {
    add_pose(*estimate.rig_from_world[j], *truth.rig_from_world[j]);
  }
  return errors;
}

inline void PrintErrors(const char* label, const CalibrationErrors& e,
                        const FinalBundleAdjustmentSummary& summary) {
  std::printf(
      "%s: rotation %.3g deg, center %.3g, focal %.3g, pp %.3g px, k1 %.3g; "
      "rms %.3g -> %.3g px, %d observations, %d outliers, %d iterations, "
      "%.3f s\n",
      label, e.rotation_deg, e.center, e.focal_relative, e.principal_point_px,
      e.k1, summary.initial_rms_px, summary.final_rms_px, summary.num_residuals,
      summary.num_outliers, summary.num_iterations, summary.seconds);
}

// Exact data from a perturbed start: the truth to rounding, no residual,
// nothing pruned.
inline void ExpectExactSolution(const SyntheticBaScene& rig, const char* label,
                                const RigCalibration& calibration,
                                const FinalBundleAdjustmentSummary& summary) {
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  PrintErrors(label, errors, summary);
  EXPECT_LT(errors.rotation_deg, 1e-8);
  EXPECT_LT(errors.center, 1e-8);
  EXPECT_LT(errors.focal_relative, 1e-9);
  EXPECT_LT(errors.principal_point_px, 1e-6);
  EXPECT_LT(errors.k1, 1e-8);
  EXPECT_LT(summary.final_rms_px, 1e-8);
  EXPECT_EQ(summary.num_outliers, 0);
}

}  // namespace final_ba_testing
}  // namespace rig_calibrator
