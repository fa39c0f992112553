// Paper §3.2, "Initial camera pose estimation": every rig image is localized
// on its own against the map, before anything is known about the rig.
//
// Three kinds of single-image estimate serve the paper's methods:
//  - kRadial (1dr): the 1D radial pose (R, tx, ty; tz unknown) by LO-RANSAC on
//    the 5-point solver. Needs only the principal point, taken as the camera's
//    initial one (the image center unless given).
//  - kKnownIntrinsics (known, known_refine, known_ra): the full pose with the
//    given intrinsics, by COLMAP's P3P LO-RANSAC (EstimateAbsolutePose).
//  - kPoseAndIntrinsics (rd, rd_ra): the full pose plus focal length and
//    distortion from this image alone: the radial pose, then the camera
//    upgrade (tz and intrinsics) on this image's correspondences only, as in
//    Kukelova et al. ICCV'13.
#pragma once

#include <colmap/base/camera.h>

#include <vector>

#include "src/calibration/camera_upgrader.h"
#include "src/estimators/radial_pose_estimator.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

enum class InitialPoseModel { kRadial, kKnownIntrinsics, kPoseAndIntrinsics };

struct InitialPoseOptions {
  RadialPoseEstimationOptions radial;
  // The single-image upgrade of kPoseAndIntrinsics.
  CameraUpgradeOptions upgrade;
  // Inlier threshold of the full-pose RANSAC with known intrinsics.
  double known_max_error_px = 4.0;
  // Images with fewer inliers are not localized.
  int min_num_inliers = 15;
  int num_threads = -1;
  unsigned int seed = 0;
  bool print_progress = true;
};

struct InitialPoseSummary {
  int num_images = 0;
  int num_localized = 0;
  std::vector<int> num_localized_per_camera;
  double seconds = 0;
};

// Sets, for every image of `dataset`, calibration->images[i].localized,
// single_image_cam_from_world, inlier_mask, num_inliers and radial_rms_px
// (calibration->images must be sized like dataset.images). For
// kPoseAndIntrinsics, per_image_cameras (may be null otherwise) receives each
// localized image's own intrinsics, in the model of its rig camera.
// Images are processed in parallel; results do not depend on the number of
// threads (each image has its own random seed).
void EstimateInitialPoses(const InitialPoseOptions& options,
                          InitialPoseModel model, const RigDataset& dataset,
                          RigCalibration* calibration,
                          std::vector<colmap::Camera>* per_image_cameras,
                          InitialPoseSummary* summary);

// The image's keypoints relative to `camera`'s principal point, and its map
// points, in correspondence order.
void CenteredCorrespondences(const RigImage& image,
                             const colmap::Camera& camera,
                             std::vector<Eigen::Vector2d>* points2D_centered,
                             std::vector<Eigen::Vector3d>* points3D);

}  // namespace rig_calibrator
