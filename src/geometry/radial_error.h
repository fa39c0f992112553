// The radial reprojection error of a 1D radial camera (paper §3.2), the one
// definition the solvers, estimators and stages score with. A 1D radial camera
// predicts only the half-line from the principal point on which a point's
// image lies; the error is the image point's distance from that line.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

// Squared radial reprojection error of a camera-frame point Y = R X + t
// (only Y_1, Y_2 matter) for the centered image point x:
//   z = normalize(Y_12), alpha = z^T x, e = x - alpha z,
//   |e|^2 = (z_1 x_2 - z_2 x_1)^2.
// Returns +infinity if alpha <= 0 (x lies on the opposite half-line) or if
// |Y_12| <= 1e-12 |Y| (the point is on the optical axis: no direction).
// NaN input also gives +infinity.
inline double SquaredRadialErrorInCamera(const Eigen::Vector3d& point_in_cam,
                                         const Eigen::Vector2d& point2D) {
  const double a = point_in_cam.x();
  const double b = point_in_cam.y();
  const double radial_norm_sq = a * a + b * b;
  const double alpha_times_norm = a * point2D.x() + b * point2D.y();
  if (!(alpha_times_norm > 0) ||
      !(radial_norm_sq > 1e-24 * point_in_cam.squaredNorm())) {
    return std::numeric_limits<double>::infinity();
  }
  const double cross = a * point2D.y() - b * point2D.x();
  const double error_sq = cross * cross / radial_norm_sq;
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
