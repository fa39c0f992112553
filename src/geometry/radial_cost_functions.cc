#include "src/geometry/radial_cost_functions.h"

#include <Eigen/Geometry>
#include <cmath>

namespace rig_calibrator {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d skew;
  skew << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return skew;
}

// R(w) = exp([w]x) and the right Jacobian of SO(3),
//   J_r(w) = I - (1 - cos t) / t^2 [w]x + (t - sin t) / t^3 [w]x^2, t = |w|,
// by its Taylor expansion I - [w]x / 2 + [w]x^2 / 6 for tiny t.
void RotationAndRightJacobian(const double* angle_axis,
                              Eigen::Matrix3d* rotation,
                              Eigen::Matrix3d* right_jacobian) {
  const Eigen::Map<const Eigen::Vector3d> w(angle_axis);
  const double theta_sq = w.squaredNorm();
  const Eigen::Matrix3d skew = Skew(w);
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
  const double radial_norm_sq = point_in_cam.head<2>().squaredNorm();
  if (radial_norm_sq >= 1e-20) {
    const double radial_norm = std::sqrt(radial_norm_sq);
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
    Eigen::Map<Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> jacobian(
        jacobians[0]);
    jacobian.leftCols<3>() =
        -d_cam * cam_rotation * Skew(point_in_rig) * cam_jacobian;
    jacobian.rightCols<3>() = d_cam;
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> jacobian(
        jacobians[1]);
    const Eigen::Matrix<double, 2, 3> d_rig = d_cam * cam_rotation;
    jacobian.leftCols<3>() =
        -d_rig * rig_rotation * Skew(point3D_) * rig_jacobian;
    jacobian.rightCols<3>() = d_rig;
  }
  if (jacobians[2] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 2, Eigen::RowMajor>> jacobian(
        jacobians[2]);
    jacobian = -d_centered;
  }
  return true;
}

}  // namespace rig_calibrator
