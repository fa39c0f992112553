#include "src/calibration/inlier_selection.h"

#include <unordered_map>

#include "src/calibration/capture_time_model.h"
#include "src/geometry/frameset_motion.h"
#include "src/geometry/radial_error.h"
#include "src/geometry/timed_rig_reprojection_cost.h"

namespace rig_calibrator {
namespace {

// Marks the correspondences that `is_inlier(image, camera, cam_from_world,
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
      if (is_inlier(image, camera, cam_from_world, image.correspondences[k])) {
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
                [&](const RigImage& /*image*/, const colmap::Camera& camera,
                    const Rigid3d& cam_from_world,
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
                       RigCalibration* calibration,
                       const std::vector<double>& time_offsets_s,
                       const std::vector<double>& line_delays_s) {
  const std::unordered_map<int64_t, Eigen::Vector3d>& refined =
      calibration->refined_points3D;
  const bool timed = !time_offsets_s.empty() || !line_delays_s.empty();
  std::vector<FramesetMotion> motions;
  if (timed) {
    motions = AdjustedFramesetMotions(dataset, *calibration);
  }
  const auto at = [](const std::vector<double>& values, int camera) {
    return values.empty() ? 0.0 : values[camera];
  };
  SelectInliers(
      dataset, calibration,
      [&](const RigImage& image, const colmap::Camera& camera,
          const Rigid3d& cam_from_world, const Correspondence& correspondence) {
        const auto refined_point = refined.find(correspondence.point3D_id);
        const Eigen::Vector3d& point = refined_point != refined.end()
                                           ? refined_point->second
                                           : correspondence.point3D;
        Eigen::Vector3d point_cam;
        if (timed) {
          const PoseParams rig_from_world =
              ToPoseParams(*calibration->rig_from_world[image.frameset_index]);
          const double tau = CaptureTimeOfRow(
              at(time_offsets_s, image.camera_index),
              at(line_delays_s, image.camera_index), correspondence.point2D.y());
          Eigen::Vector3d point_rig;
          WorldToRigAtOffset(rig_from_world.data(), point.data(),
                             motions[image.frameset_index],
                             &motions[image.frameset_index][9], tau,
                             point_rig.data());
          point_cam = calibration->cam_from_rig[image.camera_index] * point_rig;
        } else {
          point_cam = cam_from_world * point;
        }
        return point_cam.z() > 1e-9 &&
               (camera.WorldToImage(point_cam.hnormalized()) -
                correspondence.point2D)
                       .norm() < max_error_px;
      });
}

}  // namespace rig_calibrator
