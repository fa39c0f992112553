// The cost of the final bundle adjustment (paper §3.6): the reprojection
// error of a map point X seen by camera i of a rig in frameset j,
//
//   r = pi_theta(P Q X) - x   (pixels, 2 residuals),
//
// Q = rig_from_world of the frameset, P = cam_from_rig of the camera, theta
// the camera's COLMAP model parameters, pi_theta the model's projection of
// the normalized point (u, v) = (p_x / p_z, p_y / p_z) of p = P Q X, x the
// observed keypoint.
//
// Parameter blocks, in order: Q and P as [qw, qx, qy, qz, tx, ty, tz] (for
// ceres::QuaternionManifold x R^3: one block per pose, so that a rig pose is
// a single block of the Schur elimination group), theta (the model's
// kNumParams) and, when the point is refined, X (3).
//
// Jacobians. The pose and point Jacobians are analytic, by the chain rule
// through p = R_P (R_Q X + t_Q) + t_P:
//   dr/dp   = dpi/d(u,v) [1/z, 0, -u/z; 0, 1/z, -v/z],
//   dr/dt_P = dr/dp,                    dr/dq_P = dr/dp  dR(q_P) y / dq_P,
//   dr/dt_Q = dr/dp R_P,                dr/dq_Q = dr/dp R_P dR(q_Q) X / dq_Q,
//   dr/dX   = dr/dp R_P R_Q,
// with y = R_Q X + t_Q and dR(q) p / dq from RotatedPointQuaternionJacobian.
// In the tangent space of RigPoseManifold (EvaluateTangent: the final
// bundle adjustment's solver), q' = [cos|d|, sin|d| d / |d|] q, so
// R(q') = (I + 2 [d]x) R(q) to first order and, with the rotated parts
// a_P = R_P y, a_Q = R_Q X,
//   dr/d(d_P, t_P) = dr/dp [-2 [a_P]x, I],
//   dr/d(d_Q, t_Q) = dr/dp R_P [-2 [a_Q]x, I].
// pi_theta and its derivatives come from camera_model_jacobians.h (closed
// form for the common models): the Jacobian evaluation dominates the final
// bundle adjustment.
// A point that is not in front of the camera (p_z <= 0) is an invalid
// evaluation for Ceres (the step is rejected), not a NaN.
#pragma once

#include <ceres/cost_function.h>
#include <colmap/base/pose.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "src/geometry/camera_model_jacobians.h"
#include "src/geometry/pose_jacobians.h"
#include "src/geometry/tangent_jacobian_cost.h"

namespace rig_calibrator {

// r = pi_theta(P Q X) - x for the COLMAP model CameraModel (see the top of
// the file); X is a fixed point given at construction or the fourth block.
template <typename CameraModel>
class RigReprojectionCost final
    : public RigPosesTangentCost<RigReprojectionCost<CameraModel>> {
 public:
  static constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);

  // `point3D` null: the point is the fourth parameter block.
  RigReprojectionCost(const Eigen::Vector2d& observed,
                      const Eigen::Vector3d* point3D)
      : observed_(observed),
        fixed_point3D_(point3D != nullptr ? *point3D : Eigen::Vector3d::Zero()),
        variable_point_(point3D == nullptr) {
    this->set_num_residuals(2);
    // One allocation: a cost is made per observation (10^6).
    *this->mutable_parameter_block_sizes() =
        variable_point_ ? std::vector<int32_t>{7, 7, kNumParams, 3}
                        : std::vector<int32_t>{7, 7, kNumParams};
  }

  // Evaluate and EvaluateTangent (RigPosesTangentCost): the poses'
  // Jacobians ambient, or 2 x 6 in RigPoseManifold's tangent space.
  template <bool kTangent>
  bool EvaluateImpl(double const* const* parameters, double* residuals,
                    double** jacobians) const {
    const double* rig_from_world = parameters[0];
    const double* cam_from_rig = parameters[1];
    const double* camera_params = parameters[2];
    const Eigen::Quaterniond rig_rotation(rig_from_world[0], rig_from_world[1],
                                          rig_from_world[2], rig_from_world[3]);
    const Eigen::Quaterniond cam_rotation(cam_from_rig[0], cam_from_rig[1],
                                          cam_from_rig[2], cam_from_rig[3]);
    const Eigen::Matrix3d rig_rotation_matrix = rig_rotation.toRotationMatrix();
    const Eigen::Matrix3d cam_rotation_matrix = cam_rotation.toRotationMatrix();
    const Eigen::Vector3d point3D =
        variable_point_ ? Eigen::Vector3d(parameters[3]) : fixed_point3D_;
    const Eigen::Vector3d rig_rotated = rig_rotation_matrix * point3D;
    const Eigen::Vector3d point_in_rig =
        rig_rotated + Eigen::Vector3d(rig_from_world + 4);
    const Eigen::Vector3d cam_rotated = cam_rotation_matrix * point_in_rig;
    const Eigen::Vector3d point_in_cam =
        cam_rotated + Eigen::Vector3d(cam_from_rig + 4);
    if (jacobians == nullptr) {
      return ProjectCameraPoint<CameraModel>(camera_params, point_in_cam,
                                             observed_, residuals, nullptr,
                                             nullptr);
    }
    Eigen::Matrix<double, 2, 3> d_pixel_d_cam;
    if (!ProjectCameraPoint<CameraModel>(camera_params, point_in_cam,
                                         observed_, residuals, &d_pixel_d_cam,
                                         jacobians[2])) {
      return false;
    }
    if (jacobians[1] != nullptr) {
      WritePoseJacobian<kTangent, 2>(d_pixel_d_cam, cam_rotation,
                                     point_in_rig, cam_rotated, jacobians[1]);
    }
    const Eigen::Matrix<double, 2, 3> d_pixel_d_rig =
        d_pixel_d_cam * cam_rotation_matrix;
    if (jacobians[0] != nullptr) {
      WritePoseJacobian<kTangent, 2>(d_pixel_d_rig, rig_rotation, point3D,
                                     rig_rotated, jacobians[0]);
    }
    if (variable_point_ && jacobians[3] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jacobian(
          jacobians[3]);
      jacobian = d_pixel_d_rig * rig_rotation_matrix;
    }
    return true;
  }

 private:
  const Eigen::Vector2d observed_;
  const Eigen::Vector3d fixed_point3D_;
  const bool variable_point_;
};

// RigReprojectionCost for the COLMAP camera model `model_id`, observing
// `observed` (pixels); `point3D` fixed, or null for a refined point. Null
// for an unknown model id. The caller owns the result.
ceres::CostFunction* CreateRigReprojectionCost(int model_id,
                                               const Eigen::Vector2d& observed,
                                               const Eigen::Vector3d* point3D);

}  // namespace rig_calibrator
