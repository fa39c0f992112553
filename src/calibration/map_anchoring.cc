#include "src/calibration/map_anchoring.h"

#include <Eigen/Geometry>
#include <cmath>
#include <unordered_map>

namespace rig_calibrator {
namespace {

// Applies the similarity X' = s R X + t (similarity = [s R, t]) to the
// refined points, rig poses, cam_from_rig translations and map image poses,
// leaving every projection unchanged (see the header).
void ApplySimilarity(const Eigen::Matrix4d& similarity,
                     RigCalibration* calibration) {
  const Eigen::Matrix3d scaled_rotation = similarity.topLeftCorner<3, 3>();
  const double scale = std::cbrt(scaled_rotation.determinant());
  const Eigen::Matrix3d rotation = scaled_rotation / scale;
  const Eigen::Vector3d translation = similarity.topRightCorner<3, 1>();
  for (auto& [point3D_id, point] : calibration->refined_points3D) {
    point = scaled_rotation * point + translation;
  }
  const auto move_pose = [&](Rigid3d* x_from_world) {
    const Eigen::Matrix3d new_rotation =
        x_from_world->RotationMatrix() * rotation.transpose();
    *x_from_world = Rigid3d(new_rotation, scale * x_from_world->translation -
                                              new_rotation * translation);
  };
  for (std::optional<Rigid3d>& rig_from_world : calibration->rig_from_world) {
    if (rig_from_world) {
      move_pose(&*rig_from_world);
    }
  }
  for (Rigid3d& cam_from_world : calibration->map_cam_from_world) {
    move_pose(&cam_from_world);
  }
  for (Rigid3d& cam_from_rig : calibration->cam_from_rig) {
    cam_from_rig.translation *= scale;
  }
}

}  // namespace

bool AnchorRefinedPointsToMap(const RigDataset& dataset,
                              RigCalibration* calibration) {
  const std::unordered_map<int64_t, Eigen::Vector3d>& refined_points =
      calibration->refined_points3D;
  if (refined_points.size() < 3) {
    return false;
  }
  // A refined point's map position: map_points3D's, else that of its first
  // correspondence. Only the refined points are looked up (copying the whole
  // map instead took 13 of AdjustRig's 500 ms at 100 framesets x 10 cameras).
  Eigen::Matrix3Xd refined(3, refined_points.size());
  Eigen::Matrix3Xd mapped(3, refined_points.size());
  std::unordered_map<int64_t, Eigen::Index> unmapped_columns;
  Eigen::Index column = 0;
  for (const auto& [point3D_id, point] : refined_points) {
    refined.col(column) = point;
    const auto it = dataset.map_points3D.find(point3D_id);
    if (it != dataset.map_points3D.end()) {
      mapped.col(column) = it->second;
    } else {
      unmapped_columns.emplace(point3D_id, column);
    }
    ++column;
  }
  for (const RigImage& image : dataset.images) {
    if (unmapped_columns.empty()) break;
    for (const Correspondence& correspondence : image.correspondences) {
      const auto it = unmapped_columns.find(correspondence.point3D_id);
      if (it != unmapped_columns.end()) {
        mapped.col(it->second) = correspondence.point3D;
        unmapped_columns.erase(it);
      }
    }
  }
  if (!unmapped_columns.empty()) return false;
  ApplySimilarity(Eigen::umeyama(refined, mapped, true), calibration);
  return true;
}

bool AnchorMapImagesToMap(const RigDataset& dataset,
                          RigCalibration* calibration) {
  const size_t num_images = dataset.map_images.size();
  if (num_images < 3 || calibration->map_cam_from_world.size() != num_images) {
    return false;
  }
  Eigen::Matrix3Xd adjusted(3, num_images);
  Eigen::Matrix3Xd mapped(3, num_images);
  for (size_t i = 0; i < num_images; ++i) {
    adjusted.col(i) = calibration->map_cam_from_world[i].Center();
    mapped.col(i) = dataset.map_images[i].cam_from_world.Center();
  }
  ApplySimilarity(Eigen::umeyama(adjusted, mapped, true), calibration);
  return true;
}

}  // namespace rig_calibrator
