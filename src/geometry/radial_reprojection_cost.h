// Ceres cost functor (automatic differentiation) of the radial reprojection
// error of one image point under a cam_from_world pose: the refinement of a
// single radial pose (paper §3.2).
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>

#include "src/geometry/radial_residual.h"

namespace rig_calibrator {

// Radial reprojection error of one 2D-3D correspondence under a
// cam_from_world pose (q, t):
//   Y = R(q) X + t,  e = RadialResidual(x, Y)   (2 components),
// with x the image point relative to the principal point. Parameters: the
// rotation as a unit quaternion (w, x, y, z) (use ceres::QuaternionManifold)
// and the translation (tx, ty, tz); tz only enters the optical-axis test, its
// derivative is 0 (hold it constant, e.g. with ceres::SubsetManifold(3, {2})).
class RadialReprojectionCost {
 public:
  RadialReprojectionCost(const Eigen::Vector2d& point2D_centered,
                         const Eigen::Vector3d& point3D)
      : point2D_(point2D_centered), point3D_(point3D) {}

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D_centered,
                                     const Eigen::Vector3d& point3D) {
    return new ceres::AutoDiffCostFunction<RadialReprojectionCost, 2, 4, 3>(
        new RadialReprojectionCost(point2D_centered, point3D));
  }

  template <typename T>
  bool operator()(const T* cam_from_world_rotation,
                  const T* cam_from_world_translation, T* residuals) const {
    const T point3D[3] = {T(point3D_(0)), T(point3D_(1)), T(point3D_(2))};
    T point_in_cam[3];
    ceres::UnitQuaternionRotatePoint(cam_from_world_rotation, point3D,
                                     point_in_cam);
    for (int k = 0; k < 3; ++k) {
      point_in_cam[k] += cam_from_world_translation[k];
    }
    const T point2D[2] = {T(point2D_(0)), T(point2D_(1))};
    RadialResidual(point2D, point_in_cam, residuals);
    return true;
  }

 private:
  const Eigen::Vector2d point2D_;
  const Eigen::Vector3d point3D_;
};

}  // namespace rig_calibrator
