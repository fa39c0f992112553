// The pose deviation d(T, P Q) of the rig initialization's eq. 4 (paper
// §3.3) as a Ceres cost: for an image with per-image pose T (camera from
// world) and scene center X (the centroid of its map points),
//   r = ( angle-axis of R_T^T R_P R_Q                        (3, radians),
//         w * rows 0..kRows-1 of (P Q X - T X)               (kRows, map units)
//         ),
// with w = translation_weight (radians per map unit). kRows = 2 for 1D radial
// poses (tz unknown), 3 for full poses. Comparing the camera-frame positions
// of X rather than the translations keeps the residual independent of the
// distance of the map's origin. Parameters: P (cam_from_rig) and Q
// (rig_from_world), each as (angle-axis, translation).
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <array>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

template <int kRows>
class PoseDeviationCost {
 public:
  PoseDeviationCost(const Rigid3d& cam_from_world,
                    const Eigen::Vector3d& scene_center,
                    double translation_weight)
      : inverse_rotation_{cam_from_world.rotation.w(),
                          -cam_from_world.rotation.x(),
                          -cam_from_world.rotation.y(),
                          -cam_from_world.rotation.z()},
        scene_center_(scene_center),
        observed_center_(cam_from_world * scene_center),
        translation_weight_(translation_weight) {}

  static ceres::CostFunction* Create(const Rigid3d& cam_from_world,
                                     const Eigen::Vector3d& scene_center,
                                     double translation_weight) {
    return new ceres::AutoDiffCostFunction<PoseDeviationCost, 3 + kRows, 6, 6>(
        new PoseDeviationCost(cam_from_world, scene_center,
                              translation_weight));
  }

  template <typename T>
  bool operator()(const T* cam_from_rig, const T* rig_from_world,
                  T* residuals) const {
    T cam_quaternion[4], rig_quaternion[4], composed[4], difference[4];
    ceres::AngleAxisToQuaternion(cam_from_rig, cam_quaternion);
    ceres::AngleAxisToQuaternion(rig_from_world, rig_quaternion);
    ceres::QuaternionProduct(cam_quaternion, rig_quaternion, composed);
    const T inverse_rotation[4] = {
        T(inverse_rotation_[0]), T(inverse_rotation_[1]),
        T(inverse_rotation_[2]), T(inverse_rotation_[3])};
    ceres::QuaternionProduct(inverse_rotation, composed, difference);
    ceres::QuaternionToAngleAxis(difference, residuals);
    const T scene_center[3] = {T(scene_center_(0)), T(scene_center_(1)),
                               T(scene_center_(2))};
    T in_rig[3], in_cam[3];
    ceres::AngleAxisRotatePoint(rig_from_world, scene_center, in_rig);
    for (int r = 0; r < 3; ++r) in_rig[r] += rig_from_world[3 + r];
    ceres::AngleAxisRotatePoint(cam_from_rig, in_rig, in_cam);
    for (int r = 0; r < kRows; ++r) {
      residuals[3 + r] =
          T(translation_weight_) *
          (in_cam[r] + cam_from_rig[3 + r] - T(observed_center_(r)));
    }
    return true;
  }

 private:
  const std::array<double, 4> inverse_rotation_;  // R_T^T as (w, x, y, z)
  const Eigen::Vector3d scene_center_;
  const Eigen::Vector3d observed_center_;  // T X
  const double translation_weight_;
};

}  // namespace rig_calibrator
