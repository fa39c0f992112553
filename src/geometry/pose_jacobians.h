// Derivatives of a point moved by a pose block [qw, qx, qy, qz, tx, ty, tz]
// (PoseParams, rigid3d.h), p' = R(q) p + t, shared by the bundle
// adjustments' costs (rig_reprojection_cost.h, timed_rig_reprojection_cost.h,
// radial_rig_cost_function.h).
#pragma once

#include <ceres/manifold.h>
#include <ceres/product_manifold.h>
#include <colmap/base/pose.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace rig_calibrator {

// The manifold of a pose block: Ceres' quaternion (left-multiplied update
// q' = [cos|d|, sin|d| d / |d|] q) times R^3; tangent (d, t).
using RigPoseManifold = ceres::ProductManifold<ceres::QuaternionManifold,
                                               ceres::EuclideanManifold<3>>;

// d(R(q) p)/dq for a unit quaternion q = (w, v), as a 3 x 4 matrix over
// (w, v_x, v_y, v_z) (ambient Jacobians): from
//   R(q) p = p + 2 w (v x p) + 2 v x (v x p),
//   d/dw = 2 v x p,  d/dv = -2 w [p]x + 2 (v p^T + (v.p) I - 2 p v^T).
inline Eigen::Matrix<double, 3, 4> RotatedPointQuaternionJacobian(
    const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d v = q.vec();
  Eigen::Matrix<double, 3, 4> jacobian;
  jacobian.col(0) = 2 * v.cross(p);
  jacobian.rightCols<3>() =
      -2 * q.w() * colmap::CrossProductMatrix(p) +
      2 * (v * p.transpose() + v.dot(p) * Eigen::Matrix3d::Identity() -
           2 * p * v.transpose());
  return jacobian;
}

// d r / d d for r a function of p' with d r / d p' = `d_point` (rows x 3),
// at d = 0 of RigPoseManifold's rotation update, given the rotated part
// a = R(q) p: R(q') = (I + 2 [d]x) R(q) to first order, so
//   d r / d d = d_point (-2 [a]x),  row by row 2 (a x g)^T for a row g.
template <int kRows>
Eigen::Matrix<double, kRows, 3> RotationTangentJacobian(
    const Eigen::Matrix<double, kRows, 3>& d_point,
    const Eigen::Vector3d& rotated) {
  Eigen::Matrix<double, kRows, 3> jacobian;
  for (int row = 0; row < kRows; ++row) {
    jacobian.row(row) =
        2 * rotated.cross(Eigen::Vector3d(d_point.row(row).transpose()))
                .transpose();
  }
  return jacobian;
}

// The Jacobian of a residual r over a pose block, [dr/d(rotation), dr/dt],
// given dr/d(R p + t) = `d_point` (rows x 3), the pose's rotation, the point
// p it moves and its rotated part R p: ambient over (q, t), rows x 7, or
// (kTangent) over RigPoseManifold's (d, t), rows x 6; row-major into
// `jacobian`.
template <bool kTangent, int kRows>
void WritePoseJacobian(const Eigen::Matrix<double, kRows, 3>& d_point,
                       const Eigen::Quaterniond& rotation,
                       const Eigen::Vector3d& unrotated,
                       const Eigen::Vector3d& rotated, double* jacobian) {
  if constexpr (kTangent) {
    Eigen::Map<Eigen::Matrix<double, kRows, 6, Eigen::RowMajor>> out(jacobian);
    out.template leftCols<3>() = RotationTangentJacobian<kRows>(d_point, rotated);
    out.template rightCols<3>() = d_point;
  } else {
    Eigen::Map<Eigen::Matrix<double, kRows, 7, Eigen::RowMajor>> out(jacobian);
    out.template leftCols<4>() =
        d_point * RotatedPointQuaternionJacobian(rotation, unrotated);
    out.template rightCols<3>() = d_point;
  }
}

}  // namespace rig_calibrator
