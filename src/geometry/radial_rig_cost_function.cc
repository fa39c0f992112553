#include "src/geometry/radial_rig_cost_function.h"

#include <Eigen/Geometry>

#include "src/geometry/radial_residual.h"

namespace rig_calibrator {

RadialRigCostFunction::RadialRigCostFunction(const Eigen::Vector2d& point2D,
                                             const Eigen::Vector3d& point3D)
    : point2D_(point2D), point3D_(point3D) {
  set_num_residuals(2);
  *mutable_parameter_block_sizes() = {7, 7, 2};
}

bool RadialRigCostFunction::Evaluate(double const* const* parameters,
                                     double* residuals,
                                     double** jacobians) const {
  return EvaluateImpl</*kTangent=*/false>(parameters, residuals, jacobians);
}

int RadialRigCostFunction::TangentSize(int parameter_block) const {
  return parameter_block == 0 ? 5 : parameter_block == 1 ? 6 : 0;
}

bool RadialRigCostFunction::EvaluateTangent(double const* const* parameters,
                                            double* residuals,
                                            double** jacobians) const {
  return EvaluateImpl</*kTangent=*/true>(parameters, residuals, jacobians);
}

template <bool kTangent>
bool RadialRigCostFunction::EvaluateImpl(double const* const* parameters,
                                         double* residuals,
                                         double** jacobians) const {
  const double* cam_from_rig = parameters[0];
  const double* rig_from_world = parameters[1];
  const double* principal_point = parameters[2];
  const Eigen::Quaterniond cam_quaternion(cam_from_rig[0], cam_from_rig[1],
                                          cam_from_rig[2], cam_from_rig[3]);
  const Eigen::Quaterniond rig_quaternion(rig_from_world[0], rig_from_world[1],
                                          rig_from_world[2], rig_from_world[3]);
  const Eigen::Matrix3d cam_rotation = cam_quaternion.toRotationMatrix();
  const Eigen::Matrix3d rig_rotation = rig_quaternion.toRotationMatrix();
  const Eigen::Vector3d rig_rotated = rig_rotation * point3D_;
  const Eigen::Vector3d point_in_rig =
      rig_rotated + Eigen::Map<const Eigen::Vector3d>(rig_from_world + 4);
  const Eigen::Vector3d cam_rotated = cam_rotation * point_in_rig;
  const Eigen::Vector3d point_in_cam =
      cam_rotated + Eigen::Map<const Eigen::Vector3d>(cam_from_rig + 4);
  const Eigen::Vector2d centered(point2D_.x() - principal_point[0],
                                 point2D_.y() - principal_point[1]);
  RadialResidual(centered.data(), point_in_cam.data(), residuals);
  if (jacobians == nullptr) return true;

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
    if constexpr (kTangent) {
      Eigen::Map<Eigen::Matrix<double, 2, 5, Eigen::RowMajor>> jacobian(
          jacobians[0]);
      jacobian.leftCols<3>() = RotationTangentJacobian<2>(d_cam, cam_rotated);
      jacobian.rightCols<2>() = d_point;
    } else {
      Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> jacobian(
          jacobians[0]);
      jacobian.leftCols<4>() =
          d_cam * RotatedPointQuaternionJacobian(cam_quaternion, point_in_rig);
      jacobian.rightCols<3>() = d_cam;
    }
  }
  if (jacobians[1] != nullptr) {
    const Eigen::Matrix<double, 2, 3> d_rig = d_cam * cam_rotation;
    WritePoseJacobian<kTangent, 2>(d_rig, rig_quaternion, point3D_,
                                   rig_rotated, jacobians[1]);
  }
  if (jacobians[2] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 2, 2, Eigen::RowMajor>> jacobian(
        jacobians[2]);
    jacobian = -d_centered;
  }
  return true;
}

}  // namespace rig_calibrator
