#include "src/synthetic/capture_model.h"

#include <colmap/base/camera_models.h>

#include <cmath>

namespace rig_calibrator {

Rigid3d ImageCapture::CamFromWorldAt(double time_s) const {
  const Rigid3d world_from_body =
      world_from_trajectory
          ? *world_from_trajectory * trajectory->WorldFromBody(time_s)
          : trajectory->WorldFromBody(time_s);
  return cam_from_rig * (world_from_body * body_from_rig).Inverse();
}

std::vector<Rigid3d> CamFromWorldPerRow(const ImageCapture& capture,
                                        int num_rows) {
  std::vector<Rigid3d> poses;
  poses.reserve(num_rows);
  for (int row = 0; row < num_rows; ++row) {
    poses.push_back(capture.CamFromWorldAt(capture.RowTime(row + 0.5)));
  }
  return poses;
}

Rigid3d RigFromWorldAtTime(const RigGroundTruth& truth, double time_s) {
  return (truth.trajectory->WorldFromBody(time_s) * truth.body_from_rig)
      .Inverse();
}

ImageCapture CaptureOfImage(const RigGroundTruth& truth, int camera,
                            int frameset) {
  ImageCapture capture;
  capture.trajectory = &*truth.trajectory;
  capture.body_from_rig = truth.body_from_rig;
  capture.cam_from_rig = truth.cam_from_rig[camera];
  capture.top_row_time_s =
      truth.frameset_times_s[frameset] + truth.time_offsets_s[camera];
  capture.line_delay_s = truth.line_delays_s[camera];
  return capture;
}

bool ProjectWithRollingShutter(const colmap::Camera& camera,
                               const ImageCapture& capture,
                               const Eigen::Vector3d& point_in_world,
                               Eigen::Vector2d* xy) {
  double y = 0.5 * camera.Height();
  for (int iteration = 0; iteration < kMaxRollingShutterIterations;
       ++iteration) {
    const Eigen::Vector3d point_in_camera =
        capture.CamFromWorldAt(capture.RowTime(y)) * point_in_world;
    if (!(point_in_camera.z() > 1e-9 * point_in_camera.norm())) {
      return false;
    }
    Eigen::Vector2d projected;
    colmap::CameraModelWorldToImage(
        camera.ModelId(), camera.Params(),
        point_in_camera.x() / point_in_camera.z(),
        point_in_camera.y() / point_in_camera.z(), &projected.x(),
        &projected.y());
    if (!projected.allFinite()) {
      return false;
    }
    // projected is the point's pixel for the pose of row y; once y reproduces
    // itself, projected is the fixed point up to L times the step.
    const double step = std::abs(projected.y() - y);
    y = projected.y();
    if (step <= kRollingShutterTolerancePx) {
      *xy = projected;
      return true;
    }
  }
  return false;
}

}  // namespace rig_calibrator
