#include "src/calibration/complete_frameset_initialization.h"

namespace rig_calibrator {
namespace {

// The complete frameset with the most inliers, or -1.
int BestCompleteFrameset(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::vector<int>>& images_by_frameset) {
  int best_frameset = -1;
  int best_num_inliers = 0;
  for (size_t j = 0; j < images_by_frameset.size(); ++j) {
    if (images_by_frameset[j].size() != dataset.cameras.size()) continue;
    int num_inliers = 0;
    for (const int i : images_by_frameset[j]) {
      num_inliers += calibration.images[i].num_inliers;
    }
    if (num_inliers > best_num_inliers) {
      best_num_inliers = num_inliers;
      best_frameset = static_cast<int>(j);
    }
  }
  return best_frameset;
}

}  // namespace

Rigid3d AverageRigFromWorld(const std::vector<Rigid3d>& estimates) {
  Eigen::Matrix3d rotation_sum = Eigen::Matrix3d::Zero();
  Eigen::Vector3d center_sum = Eigen::Vector3d::Zero();
  for (const Rigid3d& estimate : estimates) {
    rotation_sum += estimate.RotationMatrix();
    center_sum += estimate.Center();
  }
  const Eigen::Matrix3d rotation = NearestRotation(rotation_sum);
  const Eigen::Vector3d center = center_sum / estimates.size();
  return Rigid3d(rotation, -rotation * center);
}

bool InitializeRigFromCompleteFrameset(const RigDataset& dataset,
                                       RigCalibration* calibration,
                                       std::string* error) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  // Localized images, by frameset.
  std::vector<std::vector<int>> images_by_frameset(
      dataset.frameset_names.size());
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    if (calibration->images[i].localized) {
      images_by_frameset[dataset.images[i].frameset_index].push_back(i);
    }
  }
  const int best_frameset =
      BestCompleteFrameset(dataset, *calibration, images_by_frameset);
  if (best_frameset < 0) {
    *error = "none of the " + std::to_string(images_by_frameset.size()) +
             " framesets has every camera localized";
    return false;
  }
  std::vector<Rigid3d> cam_from_world(num_cameras);
  for (const int i : images_by_frameset[best_frameset]) {
    cam_from_world[dataset.images[i].camera_index] =
        *calibration->images[i].single_image_cam_from_world;
  }
  const Rigid3d world_from_ref =
      cam_from_world[dataset.reference_camera].Inverse();
  for (int c = 0; c < num_cameras; ++c) {
    calibration->cam_from_rig[c] = cam_from_world[c] * world_from_ref;
    calibration->camera_calibrated[c] = true;
  }
  calibration->cam_from_rig[dataset.reference_camera] = Rigid3d();
  for (size_t j = 0; j < images_by_frameset.size(); ++j) {
    std::vector<Rigid3d> estimates;
    for (const int i : images_by_frameset[j]) {
      estimates.push_back(
          calibration->cam_from_rig[dataset.images[i].camera_index].Inverse() *
          *calibration->images[i].single_image_cam_from_world);
    }
    if (!estimates.empty()) {
      calibration->rig_from_world[j] = AverageRigFromWorld(estimates);
    }
  }
  return true;
}

}  // namespace rig_calibrator
