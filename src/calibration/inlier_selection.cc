#include "src/calibration/inlier_selection.h"

#include <unordered_map>

#include "src/geometry/radial_error.h"

namespace rig_calibrator {
namespace {

// Marks the correspondences that `is_inlier(camera, cam_from_world,
// correspondence)` accepts (see the header).
template <typename Predicate>
void SelectInliers(const RigDataset& dataset, RigCalibration* calibration,
                   const Predicate& is_inlier) {
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    ImageResult& result = calibration->images[i];
    result.inlier_mask.assign(image.correspondences.size(), 0);
    result.num_inliers = 0;
    if (!FramesetPosed(*calibration, image)) continue;
    const Rigid3d cam_from_world =
        calibration->CamFromWorld(image.camera_index, image.frameset_index);
    const colmap::Camera& camera = calibration->cameras[image.camera_index];
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      if (is_inlier(camera, cam_from_world, image.correspondences[k])) {
        result.inlier_mask[k] = 1;
        ++result.num_inliers;
      }
    }
  }
}

}  // namespace

bool FramesetPosed(const RigCalibration& calibration, const RigImage& image) {
  return calibration.camera_calibrated[image.camera_index] &&
         calibration.rig_from_world[image.frameset_index].has_value();
}

void SelectRadialInliers(const RigDataset& dataset, double max_error_px,
                         RigCalibration* calibration) {
  SelectInliers(dataset, calibration,
                [&](const colmap::Camera& camera, const Rigid3d& cam_from_world,
                    const Correspondence& correspondence) {
                  const Eigen::Vector2d principal_point(
                      camera.PrincipalPointX(), camera.PrincipalPointY());
                  return RadialReprojectionError(
                             cam_from_world,
                             correspondence.point2D - principal_point,
                             correspondence.point3D) < max_error_px;
                });
}

void SelectFullInliers(const RigDataset& dataset, double max_error_px,
                       RigCalibration* calibration) {
  const std::unordered_map<int64_t, Eigen::Vector3d>& refined =
      calibration->refined_points3D;
  SelectInliers(dataset, calibration,
                [&](const colmap::Camera& camera, const Rigid3d& cam_from_world,
                    const Correspondence& correspondence) {
                  const auto point = refined.find(correspondence.point3D_id);
                  const Eigen::Vector3d point_cam =
                      cam_from_world * (point != refined.end()
                                            ? point->second
                                            : correspondence.point3D);
                  return point_cam.z() > 1e-9 &&
                         (camera.WorldToImage(point_cam.hnormalized()) -
                          correspondence.point2D)
                                 .norm() < max_error_px;
                });
}

}  // namespace rig_calibrator
