// The cost of the camera upgrade's refinement (paper §3.5, camera_upgrader.h):
// the full reprojection error of a correspondence once the 1D radial
// camera's pose is known up to its translation along the optical axis.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "src/geometry/camera_model_jacobians.h"

namespace rig_calibrator {

// Full reprojection residual of one correspondence:
//   r = pi_theta(a / (c + tz), b / (c + tz)) - observed pixel,
// (a, b, c) the point in the radial camera's frame, pi_theta COLMAP's camera
// model. Jacobians: dr/dtheta and dr/d(u, v) from camera_model_jacobians.h
// (closed form for the common models), dr/dtz = -dr/d(u, v) (u, v) / (c +
// tz). Points on or behind the camera plane (c + tz <= 0) cannot be
// projected: the evaluation fails, so the LM rejects steps that would move an
// inlier behind the camera.
template <typename CameraModel>
class FullReprojectionCost final
    : public ceres::SizedCostFunction<2, 1, CameraModel::kNumParams> {
 public:
  FullReprojectionCost(const Eigen::Vector2d& point2D,
                       const Eigen::Vector3d& point_cam)
      : point2D_(point2D), point_cam_(point_cam) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double depth = point_cam_.z() + parameters[0][0];
    if (!(depth > 0)) {
      return false;
    }
    const double u = point_cam_.x() / depth;
    const double v = point_cam_.y() / depth;
    if (jacobians == nullptr) {
      CameraModel::WorldToImage(parameters[1], u, v, &residuals[0],
                                &residuals[1]);
    } else {
      Eigen::Matrix2d d_pixel_d_uv;
      ProjectWithJacobians<CameraModel>(parameters[1], u, v, residuals,
                                        &d_pixel_d_uv, jacobians[1]);
      if (jacobians[0] != nullptr) {
        const Eigen::Vector2d d_pixel_d_tz =
            -d_pixel_d_uv * Eigen::Vector2d(u, v) / depth;
        jacobians[0][0] = d_pixel_d_tz.x();
        jacobians[0][1] = d_pixel_d_tz.y();
      }
    }
    residuals[0] -= point2D_.x();
    residuals[1] -= point2D_.y();
    return true;
  }

 private:
  const Eigen::Vector2d point2D_;
  const Eigen::Vector3d point_cam_;
};

}  // namespace rig_calibrator
