// Shared by the radial pose solver and estimator tests: random poses, the
// radial camera's projection and the pose that a plane cannot tell from the
// true one.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace testing {

// Uniformly distributed rotation (a normalized 4D Gaussian).
inline Eigen::Quaterniond RandomRotation(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(*rng), normal(*rng), normal(*rng),
                            normal(*rng))
      .normalized();
}

// Equidistant fisheye with focal length f (pixels), principal point at the
// origin: the image radius is f theta for a ray at angle theta from the
// optical axis. Any radial function would do for a radial camera.
inline Eigen::Vector2d ProjectEquidistant(const Eigen::Vector3d& point_in_cam,
                                          double focal_px) {
  const double radial_norm = point_in_cam.head<2>().norm();
  const double theta = std::atan2(radial_norm, point_in_cam.z());
  return focal_px * theta * point_in_cam.head<2>() / radial_norm;
}

// The radial pose that fits every point of the plane n.X = d as well as
// `pose`: reflect the world through the plane, X' = X - 2 n (n.X - d), which
// fixes its points; the first two rows R S (S = I - 2 n n^T) and
// t12' = t12 + 2 d (R n)_12 then give a rotation with r3 = r1 x r2.
inline Rigid3d MirrorThroughPlane(const Rigid3d& pose, const Eigen::Vector3d& n,
                                  double d) {
  const Eigen::Matrix3d reflection =
      Eigen::Matrix3d::Identity() - 2 * n * n.transpose();
  Eigen::Matrix3d rotation = pose.RotationMatrix() * reflection;
  rotation.row(2) = rotation.row(0).cross(rotation.row(1));
  Eigen::Vector3d translation =
      pose.translation + 2 * d * (pose.RotationMatrix() * n);
  translation.z() = 0;
  return Rigid3d(rotation, translation);
}

}  // namespace testing
}  // namespace rig_calibrator
