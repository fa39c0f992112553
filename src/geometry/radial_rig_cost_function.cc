#include "src/geometry/radial_rig_cost_function.h"

#include <colmap/base/pose.h>

#include <Eigen/Geometry>
#include <cmath>

#include "src/geometry/radial_residual.h"

namespace rig_calibrator {
namespace {

// R(w) = exp([w]x) and the right Jacobian of SO(3),
//   J_r(w) = I - (1 - cos t) / t^2 [w]x + (t - sin t) / t^3 [w]x^2, t = |w|,
// by its Taylor expansion I - [w]x / 2 + [w]x^2 / 6 for tiny t.
void RotationAndRightJacobian(const double* angle_axis,
                              Eigen::Matrix3d* rotation,
                              Eigen::Matrix3d* right_jacobian) {
  const Eigen::Map<const Eigen::Vector3d> w(angle_axis);
  const double theta_sq = w.squaredNorm();
  const Eigen::Matrix3d skew = colmap::CrossProductMatrix(w);
  if (theta_sq < 1e-16) {
    *rotation = Eigen::Matrix3d::Identity() + skew;
    if (right_jacobian != nullptr) {
      *right_jacobian =
          Eigen::Matrix3d::Identity() - 0.5 * skew + skew * skew / 6.0;
    }
    return;
  }
  const double theta = std::sqrt(theta_sq);
  *rotation = Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
  if (right_jacobian != nullptr) {
    *right_jacobian =
        Eigen::Matrix3d::Identity() - (1 - std::cos(theta)) / theta_sq * skew +
        (theta - std::sin(theta)) / (theta_sq * theta) * skew * skew;
  }
}

// The 2x6 Jacobian of e by a pose block (w, t) that maps v to R(w) v + t,
// given d_out = de/d(R(w) v + t):
//   de/dw = -d_out R(w) [v]x J_r(w),  de/dt = d_out.
void WritePoseJacobian(const Eigen::Matrix<double, 2, 3>& d_out,
                       const Eigen::Matrix3d& rotation,
                       const Eigen::Vector3d& point,
                       const Eigen::Matrix3d& right_jacobian,
                       double* jacobian_row_major) {
  Eigen::Map<Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> jacobian(
      jacobian_row_major);
  jacobian.leftCols<3>() =
      -d_out * rotation * colmap::CrossProductMatrix(point) * right_jacobian;
  jacobian.rightCols<3>() = d_out;
}

}  // namespace

bool RadialRigCostFunction::Evaluate(double const* const* parameters,
                                     double* residuals,
                                     double** jacobians) const {
  const double* cam_from_rig = parameters[0];
  const double* rig_from_world = parameters[1];
  const double* principal_point = parameters[2];
  const bool want_jacobians = jacobians != nullptr;
  Eigen::Matrix3d rig_rotation, cam_rotation, rig_jacobian, cam_jacobian;
  RotationAndRightJacobian(rig_from_world, &rig_rotation,
                           want_jacobians ? &rig_jacobian : nullptr);
  RotationAndRightJacobian(cam_from_rig, &cam_rotation,
                           want_jacobians ? &cam_jacobian : nullptr);
  const Eigen::Vector3d point_in_rig =
      rig_rotation * point3D_ +
      Eigen::Map<const Eigen::Vector3d>(rig_from_world + 3);
  const Eigen::Vector3d point_in_cam =
      cam_rotation * point_in_rig +
      Eigen::Map<const Eigen::Vector3d>(cam_from_rig + 3);
  const Eigen::Vector2d centered(point2D_.x() - principal_point[0],
                                 point2D_.y() - principal_point[1]);
  RadialResidual(centered.data(), point_in_cam.data(), residuals);
  if (!want_jacobians) return true;

  // de/d(p0, p1) and de/d(x - c), as in RadialResidual's cases.
  Eigen::Matrix2d d_point = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d d_centered = Eigen::Matrix2d::Identity();
  if (!IsOnOpticalAxis(point_in_cam)) {
    const double radial_norm = point_in_cam.head<2>().norm();
    const Eigen::Vector2d z = point_in_cam.head<2>() / radial_norm;
    const double alpha = z.dot(centered);
    if (alpha > 0) {
      const Eigen::Matrix2d projector =
          Eigen::Matrix2d::Identity() - z * z.transpose();
      d_point =
          -(z * centered.transpose() + alpha * Eigen::Matrix2d::Identity()) *
          projector / radial_norm;
      d_centered = projector;
    }
  }
  // de/d(point_in_cam), with the (irrelevant) third coordinate.
  Eigen::Matrix<double, 2, 3> d_cam = Eigen::Matrix<double, 2, 3>::Zero();
  d_cam.leftCols<2>() = d_point;
  if (jacobians[0] != nullptr) {
    WritePoseJacobian(d_cam, cam_rotation, point_in_rig, cam_jacobian,
                      jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    WritePoseJacobian(d_cam * cam_rotation, rig_rotation, point3D_,
                      rig_jacobian, jacobians[1]);
  }
  if (jacobians[2] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 2, Eigen::RowMajor>> jacobian(
        jacobians[2]);
    jacobian = -d_centered;
  }
  return true;
}

}  // namespace rig_calibrator
