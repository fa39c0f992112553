#include "src/geometry/rigid3d.h"

#include <ceres/rotation.h>
#include <colmap/util/math.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace rig_calibrator {

Eigen::Matrix<double, 3, 4> Rigid3d::ToMatrix() const {
  Eigen::Matrix<double, 3, 4> matrix;
  matrix.leftCols<3>() = RotationMatrix();
  matrix.col(3) = translation;
  return matrix;
}

Rigid3d Rigid3d::Inverse() const {
  const Eigen::Quaterniond inverse_rotation = rotation.conjugate();
  return Rigid3d(inverse_rotation, -(inverse_rotation * translation));
}

Rigid3d Rigid3d::FromQvecTvec(const Eigen::Vector4d& qvec,
                              const Eigen::Vector3d& tvec) {
  return Rigid3d(Eigen::Quaterniond(qvec(0), qvec(1), qvec(2), qvec(3)), tvec);
}

Rigid3d operator*(const Rigid3d& a_from_b, const Rigid3d& b_from_c) {
  return Rigid3d(
      a_from_b.rotation * b_from_c.rotation,
      a_from_b.rotation * b_from_c.translation + a_from_b.translation);
}

double RotationDifferenceRad(const Eigen::Quaterniond& a,
                             const Eigen::Quaterniond& b) {
  const Eigen::Quaterniond difference = (a.conjugate() * b).normalized();
  return 2.0 * std::atan2(difference.vec().norm(), std::abs(difference.w()));
}

double RotationDifferenceDeg(const Eigen::Quaterniond& a,
                             const Eigen::Quaterniond& b) {
  return colmap::RadToDeg(RotationDifferenceRad(a, b));
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& matrix) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) =
      (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1 : -1;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

std::array<double, 6> ToAngleAxisTranslation(const Rigid3d& pose) {
  std::array<double, 6> parameters;
  const double quaternion[4] = {pose.rotation.w(), pose.rotation.x(),
                                pose.rotation.y(), pose.rotation.z()};
  ceres::QuaternionToAngleAxis(quaternion, parameters.data());
  for (int r = 0; r < 3; ++r) parameters[3 + r] = pose.translation(r);
  return parameters;
}

PoseParams ToPoseParams(const Rigid3d& pose) {
  return {pose.rotation.w(),   pose.rotation.x(),    pose.rotation.y(),
          pose.rotation.z(),   pose.translation.x(), pose.translation.y(),
          pose.translation.z()};
}

Rigid3d FromPoseParams(const PoseParams& params) {
  return Rigid3d(Eigen::Quaterniond(params[0], params[1], params[2], params[3]),
                 Eigen::Vector3d(params[4], params[5], params[6]));
}

Rigid3d FromAngleAxisTranslation(const std::array<double, 6>& parameters) {
  double quaternion[4];
  ceres::AngleAxisToQuaternion(parameters.data(), quaternion);
  return Rigid3d(Eigen::Quaterniond(quaternion[0], quaternion[1], quaternion[2],
                                    quaternion[3]),
                 Eigen::Vector3d(parameters[3], parameters[4], parameters[5]));
}

}  // namespace rig_calibrator
