// Cost function with analytic Jacobians of the radial reprojection error of
// one image point of a rig camera: the radial bundle adjustment's cost
// (paper §3.3, eq. 3).
#pragma once

#include <ceres/manifold.h>
#include <ceres/product_manifold.h>

#include <Eigen/Core>

#include "src/geometry/pose_jacobians.h"
#include "src/geometry/tangent_jacobian_cost.h"

namespace rig_calibrator {

// The manifold of a radial camera's cam_from_rig block [q, t]: RigPoseManifold
// with t_z held (it does not enter the radial error); tangent (d, t_x, t_y).
using RadialCameraPoseManifold =
    ceres::ProductManifold<ceres::QuaternionManifold, ceres::SubsetManifold>;
inline RadialCameraPoseManifold MakeRadialCameraPoseManifold() {
  return RadialCameraPoseManifold(ceres::QuaternionManifold(),
                                  ceres::SubsetManifold(3, {2}));
}

// Radial residual of one correspondence of camera i in frameset j:
//   y = R(q_Q) X + t_Q (rig frame),  p = R(q_P) y + t_P (camera frame),
//   e = RadialResidual(x - c, p)   (radial_residual.h)
// for the cam_from_rig P and rig_from_world Q blocks [qw, qx, qy, qz, tx, ty,
// tz] (PoseParams) and the principal point c. With n = |(p0, p1)|,
// z = (p0, p1) / n and alpha = z^T (x - c) > 0, e = (x - c) - alpha z and
//   de/d(p0, p1) = -(z (x - c)^T + alpha I) (I - z z^T) / n,
//   de/dc = -(I - z z^T);
// otherwise (wrong half-line, optical axis) e = x - c, de/dp = 0 and
// de/dc = -I. Poses (pose_jacobians.h), with D = de/dp (its third column 0):
// ambient, de/dq_P = D dR(q_P) y / dq_P, de/dq_Q = D R_P dR(q_Q) X / dq_Q;
// in the tangent spaces (EvaluateTangent), cam_from_rig on
// RadialCameraPoseManifold (d_P, t_Px, t_Py) and rig_from_world on
// RigPoseManifold (d_Q, t_Q):
//   de/d(d_P, t_Px, t_Py) = [D (-2 [R_P y]x), D_{:, 0:2}],
//   de/d(d_Q, t_Q) = D R_P [-2 [R_Q X]x, I].
// No trigonometric function per residual (an angle-axis pose needs a sine,
// a cosine and the right Jacobian of SO(3) per pose and residual).
class RadialRigCostFunction final : public TangentJacobianCost {
 public:
  RadialRigCostFunction(const Eigen::Vector2d& point2D,
                        const Eigen::Vector3d& point3D);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // cam_from_rig 5 (RadialCameraPoseManifold), rig_from_world 6
  // (RigPoseManifold), the principal point ambient.
  int TangentSize(int parameter_block) const override;
  bool EvaluateTangent(double const* const* parameters, double* residuals,
                       double** jacobians) const override;

 private:
  template <bool kTangent>
  bool EvaluateImpl(double const* const* parameters, double* residuals,
                    double** jacobians) const;

  const Eigen::Vector2d point2D_;
  const Eigen::Vector3d point3D_;
};

}  // namespace rig_calibrator
