// The radial reprojection error of a 1D radial camera (paper §3.2), the one
// definition the solvers, estimators, cost functors and stages score with. A
// 1D radial camera predicts only the half-line from the principal point on
// which a point's image lies; the error is the image point's distance from
// that line.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

// A camera-frame point Y predicts no radial direction when it lies on the
// optical axis, here when
//   |Y_12|^2 <= 1e-24 |Y|^2,   i.e. its angle from the axis is <= 1e-12 rad.
// The test is relative, so it means the same in every map unit (a point 1e-9
// map units off the axis of a millimeter map is not "on" it). NaN coordinates
// count as on the axis. T may be a Ceres Jet (the comparison uses the values).
template <typename T>
inline bool IsOnOpticalAxis(const T* point_in_cam) {
  const T radial_norm_sq =
      point_in_cam[0] * point_in_cam[0] + point_in_cam[1] * point_in_cam[1];
  const T norm_sq = radial_norm_sq + point_in_cam[2] * point_in_cam[2];
  return !(radial_norm_sq > T(1e-24) * norm_sq);
}

inline bool IsOnOpticalAxis(const Eigen::Vector3d& point_in_cam) {
  return IsOnOpticalAxis(point_in_cam.data());
}

// Squared radial reprojection error of a camera-frame point Y = R X + t for
// the centered image point x:
//   z = normalize(Y_12), alpha = z^T x, e = x - alpha z,
//   |e|^2 = (z_1 x_2 - z_2 x_1)^2.
// Returns +infinity if alpha <= 0 (x lies on the opposite half-line) or if Y
// is on the optical axis (IsOnOpticalAxis: no direction). NaN or infinite
// input also gives +infinity.
inline double SquaredRadialErrorInCamera(const Eigen::Vector3d& point_in_cam,
                                         const Eigen::Vector2d& point2D) {
  const double a = point_in_cam.x();
  const double b = point_in_cam.y();
  if (!(a * point2D.x() + b * point2D.y() > 0) ||
      IsOnOpticalAxis(point_in_cam)) {
    return std::numeric_limits<double>::infinity();
  }
  const double cross = a * point2D.y() - b * point2D.x();
  const double error_sq = cross * cross / (a * a + b * b);
  // Also catches infinite input, which makes error_sq NaN or infinite.
  return error_sq < std::numeric_limits<double>::infinity()
             ? error_sq
             : std::numeric_limits<double>::infinity();
}

// Radial reprojection error |e| (see SquaredRadialErrorInCamera) of a world
// point under cam_from_world; +infinity on the wrong half-line or on the
// optical axis.
inline double RadialReprojectionError(const Rigid3d& cam_from_world,
                                      const Eigen::Vector2d& point2D_centered,
                                      const Eigen::Vector3d& point3D) {
  return std::sqrt(
      SquaredRadialErrorInCamera(cam_from_world * point3D, point2D_centered));
}

}  // namespace rig_calibrator
