// Rigid transforms in the project's convention: a transform named `a_from_b`
// maps a point from frame b to frame a, x_a = rotation * x_b + translation
// (the convention of current COLMAP). Quaternions are Hamilton, (w, x, y, z).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

namespace rig_calibrator {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& rotation,
          const Eigen::Vector3d& translation)
      : rotation(rotation.normalized()), translation(translation) {}
  Rigid3d(const Eigen::Matrix3d& rotation_matrix,
          const Eigen::Vector3d& translation)
      : rotation(Eigen::Quaterniond(rotation_matrix).normalized()),
        translation(translation) {}

  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  // [R | t], the 3x4 projection-style matrix.
  Eigen::Matrix<double, 3, 4> ToMatrix() const;
  Rigid3d Inverse() const;
  // For a cam_from_world transform: the camera center in world coordinates,
  // -R^T t.
  Eigen::Vector3d Center() const { return Inverse().translation; }

  // COLMAP 3.8 stores poses as qvec (w, x, y, z) and tvec.
  Eigen::Vector4d Qvec() const {
    return Eigen::Vector4d(rotation.w(), rotation.x(), rotation.y(),
                           rotation.z());
  }
  static Rigid3d FromQvecTvec(const Eigen::Vector4d& qvec,
                              const Eigen::Vector3d& tvec);

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const {
    return rotation * x + translation;
  }
};

// a_from_c = a_from_b * b_from_c.
Rigid3d operator*(const Rigid3d& a_from_b, const Rigid3d& b_from_c);

// Angle of R_a^T R_b, 2 atan2(|v|, |w|) of the quaternion a^-1 b = (w, v):
// unlike 2 acos(|w|) it keeps full precision for tiny angles. Radians.
double RotationDifferenceRad(const Eigen::Quaterniond& a,
                             const Eigen::Quaterniond& b);
// The same in degrees.
double RotationDifferenceDeg(const Eigen::Quaterniond& a,
                             const Eigen::Quaterniond& b);

// Angle between two (not necessarily unit) vectors, atan2(|a x b|, a . b) in
// [0, pi]: unlike acos of the normalized dot product it keeps full precision
// near 0 and pi. Radians; 0 if either vector is zero.
inline double AngleBetweenRad(const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

// A pose as one Ceres parameter block: (angle-axis of the rotation,
// translation), the minimal 6-vector of the rig initialization's refinement
// (rig_init_refinement.h).
std::array<double, 6> ToAngleAxisTranslation(const Rigid3d& pose);
Rigid3d FromAngleAxisTranslation(const std::array<double, 6>& parameters);

// A pose as one parameter block of the bundle adjustments' solver,
// [qw, qx, qy, qz, tx, ty, tz], refined on RigPoseManifold (pose_jacobians.h):
// a rig pose is a single block of the Schur elimination group.
using PoseParams = std::array<double, 7>;
PoseParams ToPoseParams(const Rigid3d& pose);
Rigid3d FromPoseParams(const PoseParams& params);

// Projects a 3x3 matrix onto the closest rotation in Frobenius norm
// (SVD, with the determinant forced to +1).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& matrix);

}  // namespace rig_calibrator
