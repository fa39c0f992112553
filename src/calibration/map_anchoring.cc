#include "src/calibration/map_anchoring.h"

#include <Eigen/Geometry>
#include <cmath>
#include <unordered_map>

namespace rig_calibrator {

bool AnchorRefinedPointsToMap(const RigDataset& dataset,
                              RigCalibration* calibration) {
  std::unordered_map<int64_t, Eigen::Vector3d>& refined_points =
      calibration->refined_points3D;
  if (refined_points.size() < 3) {
    return false;
  }
  std::unordered_map<int64_t, Eigen::Vector3d> map_points;
  for (const RigImage& image : dataset.images) {
    for (const Correspondence& correspondence : image.correspondences) {
      if (refined_points.count(correspondence.point3D_id) > 0) {
        map_points.emplace(correspondence.point3D_id, correspondence.point3D);
      }
    }
  }
  Eigen::Matrix3Xd refined(3, refined_points.size());
  Eigen::Matrix3Xd mapped(3, refined_points.size());
  int column = 0;
  for (const auto& [point3D_id, point] : refined_points) {
    refined.col(column) = point;
    mapped.col(column) = map_points.at(point3D_id);
    ++column;
  }
  const Eigen::Matrix4d similarity = Eigen::umeyama(refined, mapped, true);
  const Eigen::Matrix3d scaled_rotation = similarity.topLeftCorner<3, 3>();
  const double scale = std::cbrt(scaled_rotation.determinant());
  const Eigen::Matrix3d rotation = scaled_rotation / scale;
  const Eigen::Vector3d translation = similarity.topRightCorner<3, 1>();
  for (auto& [point3D_id, point] : refined_points) {
    point = scaled_rotation * point + translation;
  }
  for (std::optional<Rigid3d>& rig_from_world : calibration->rig_from_world) {
    if (!rig_from_world) {
      continue;
    }
    const Eigen::Matrix3d new_rotation =
        rig_from_world->RotationMatrix() * rotation.transpose();
    rig_from_world = Rigid3d(new_rotation, scale * rig_from_world->translation -
                                               new_rotation * translation);
  }
  for (Rigid3d& cam_from_rig : calibration->cam_from_rig) {
    cam_from_rig.translation *= scale;
  }
  return true;
}

}  // namespace rig_calibrator
