#include "src/calibration/initial_pose_estimation.h"

#include <colmap/estimators/pose.h>
#include <colmap/util/random.h>
#include <colmap/util/timer.h>
#include <omp.h>

#include <atomic>
#include <iostream>

namespace rig_calibrator {
namespace {

int NumThreads(int num_threads) {
  return num_threads > 0 ? num_threads : omp_get_max_threads();
}

bool EstimateRadial(const InitialPoseOptions& options, const RigImage& image,
                    const colmap::Camera& camera, ImageResult* result) {
  std::vector<Eigen::Vector2d> points2D_centered;
  std::vector<Eigen::Vector3d> points3D;
  CenteredCorrespondences(image, camera, &points2D_centered, &points3D);
  RadialPoseEstimate estimate;
  if (!EstimateRadialPose(options.radial, points2D_centered, points3D,
                          &estimate) ||
      estimate.num_inliers < options.min_num_inliers) {
    return false;
  }
  result->single_image_cam_from_world = estimate.cam_from_world;
  result->inlier_mask = std::move(estimate.inlier_mask);
  result->num_inliers = estimate.num_inliers;
  result->radial_rms_px = estimate.radial_rms_px;
  return true;
}

bool EstimateWithKnownIntrinsics(const InitialPoseOptions& options,
                                 const RigImage& image,
                                 const colmap::Camera& camera,
                                 ImageResult* result) {
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points3D;
  for (const Correspondence& correspondence : image.correspondences) {
    points2D.push_back(correspondence.point2D);
    points3D.push_back(correspondence.point3D);
  }
  colmap::AbsolutePoseEstimationOptions pose_options;
  pose_options.estimate_focal_length = false;
  pose_options.num_threads = 1;
  pose_options.ransac_options.max_error = options.known_max_error_px;
  pose_options.ransac_options.confidence = options.radial.confidence;
  pose_options.ransac_options.min_num_trials = options.radial.min_num_trials;
  pose_options.ransac_options.max_num_trials = options.radial.max_num_trials;
  pose_options.ransac_options.min_inlier_ratio =
      options.radial.min_inlier_ratio;
  Eigen::Vector4d qvec;
  Eigen::Vector3d tvec;
  colmap::Camera camera_copy = camera;
  size_t num_inliers = 0;
  std::vector<char> inlier_mask;
  if (points2D.size() < 4 ||
      !colmap::EstimateAbsolutePose(pose_options, points2D, points3D, &qvec,
                                    &tvec, &camera_copy, &num_inliers,
                                    &inlier_mask) ||
      static_cast<int>(num_inliers) < options.min_num_inliers) {
    return false;
  }
  colmap::AbsolutePoseRefinementOptions refinement;
  refinement.refine_focal_length = false;
  refinement.refine_extra_params = false;
  refinement.print_summary = false;
  colmap::RefineAbsolutePose(refinement, inlier_mask, points2D, points3D, &qvec,
                             &tvec, &camera_copy);
  result->single_image_cam_from_world = Rigid3d::FromQvecTvec(qvec, tvec);
  result->inlier_mask = std::move(inlier_mask);
  result->num_inliers = static_cast<int>(num_inliers);
  return true;
}

// The intrinsics that `refinement` holds keep `camera`'s values.
bool EstimatePoseAndIntrinsics(const InitialPoseOptions& options,
                               const RigImage& image,
                               const colmap::Camera& camera,
                               const IntrinsicsRefinement& refinement,
                               ImageResult* result,
                               colmap::Camera* image_camera) {
  if (!EstimateRadial(options, image, camera, result)) {
    return false;
  }
  // The upgrade sees the image's radial inliers in the camera frame without
  // tz: X' = R X + (tx, ty, 0).
  const Rigid3d& radial_pose = *result->single_image_cam_from_world;
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points_cam;
  std::vector<size_t> indices;
  for (size_t k = 0; k < image.correspondences.size(); ++k) {
    if (!result->inlier_mask[k]) continue;
    points2D.push_back(image.correspondences[k].point2D);
    points_cam.push_back(radial_pose * image.correspondences[k].point3D);
    indices.push_back(k);
  }
  *image_camera = camera;
  CameraUpgradeOptions upgrade_options = options.upgrade;
  upgrade_options.refine_focal_length &= refinement.focal_length;
  upgrade_options.refine_principal_point &= refinement.principal_point;
  upgrade_options.refine_extra_params &= refinement.extra_params;
  CameraUpgradeResult upgrade;
  if (!UpgradeCamera(upgrade_options, points2D, points_cam, image_camera,
                     &upgrade) ||
      upgrade.num_inliers < options.min_num_inliers) {
    result->single_image_cam_from_world.reset();
    return false;
  }
  Rigid3d full_pose = radial_pose;
  full_pose.translation.z() = upgrade.tz;
  result->single_image_cam_from_world = full_pose;
  std::fill(result->inlier_mask.begin(), result->inlier_mask.end(), 0);
  for (size_t k = 0; k < indices.size(); ++k) {
    result->inlier_mask[indices[k]] = upgrade.inlier_mask[k];
  }
  result->num_inliers = upgrade.num_inliers;
  result->rms_px = upgrade.rms_px;
  return true;
}

}  // namespace

void CenteredCorrespondences(const RigImage& image,
                             const colmap::Camera& camera,
                             std::vector<Eigen::Vector2d>* points2D_centered,
                             std::vector<Eigen::Vector3d>* points3D) {
  const Eigen::Vector2d principal_point(camera.PrincipalPointX(),
                                        camera.PrincipalPointY());
  points2D_centered->clear();
  points3D->clear();
  points2D_centered->reserve(image.correspondences.size());
  points3D->reserve(image.correspondences.size());
  for (const Correspondence& correspondence : image.correspondences) {
    points2D_centered->push_back(correspondence.point2D - principal_point);
    points3D->push_back(correspondence.point3D);
  }
}

void EstimateInitialPoses(const InitialPoseOptions& options,
                          InitialPoseModel model, const RigDataset& dataset,
                          RigCalibration* calibration,
                          std::vector<colmap::Camera>* per_image_cameras,
                          InitialPoseSummary* summary) {
  colmap::Timer timer;
  timer.Start();
  const int num_images = static_cast<int>(dataset.images.size());
  calibration->images.resize(num_images);
  if (per_image_cameras != nullptr) {
    per_image_cameras->assign(num_images, colmap::Camera());
  }
  std::atomic<int> num_done(0);
  std::atomic<int> num_localized(0);
  const int progress_step = std::max(1, num_images / 10);

#pragma omp parallel for schedule(dynamic) \
    num_threads(NumThreads(options.num_threads))
  for (int i = 0; i < num_images; ++i) {
    const RigImage& image = dataset.images[i];
    const colmap::Camera& camera = dataset.cameras[image.camera_index].camera;
    // One seed per image: the result does not depend on the thread count.
    colmap::SetPRNGSeed(options.seed + 7919u * static_cast<unsigned>(i) + 1u);
    ImageResult result;
    colmap::Camera image_camera = camera;
    bool localized = false;
    switch (model) {
      case InitialPoseModel::kRadial:
        localized = EstimateRadial(options, image, camera, &result);
        break;
      case InitialPoseModel::kKnownIntrinsics:
        localized =
            EstimateWithKnownIntrinsics(options, image, camera, &result);
        break;
      case InitialPoseModel::kPoseAndIntrinsics:
        localized = EstimatePoseAndIntrinsics(
            options, image, camera,
            dataset.cameras[image.camera_index].refinement, &result,
            &image_camera);
        break;
    }
    result.localized = localized;
    if (!localized) {
      result = ImageResult();
    } else {
      ++num_localized;
    }
    calibration->images[i] = std::move(result);
    if (per_image_cameras != nullptr && localized) {
      (*per_image_cameras)[i] = image_camera;
    }
    const int done = ++num_done;
    if (options.print_progress &&
        (done % progress_step == 0 || done == num_images)) {
#pragma omp critical(initial_pose_progress)
      std::cout << "  " << done << "/" << num_images << " images processed, "
                << num_localized.load() << " localized" << std::endl;
    }
  }

  if (summary != nullptr) {
    summary->num_images = num_images;
    summary->num_localized = num_localized.load();
    summary->num_localized_per_camera.assign(dataset.cameras.size(), 0);
    for (int i = 0; i < num_images; ++i) {
      if (calibration->images[i].localized) {
        ++summary->num_localized_per_camera[dataset.images[i].camera_index];
      }
    }
    summary->seconds = timer.ElapsedSeconds();
  }
}

}  // namespace rig_calibrator
