// The radial residual vector of a 1D radial camera (paper §3.2-3.4), the
// quantity the Ceres cost functors minimize: the same error as
// radial_error.h, as a 2-vector with a robust continuation on the wrong
// half-line.
#pragma once

#include <ceres/jet.h>

#include "src/geometry/radial_error.h"

namespace rig_calibrator {

// Radial residual of a camera-frame point Y = (a, b, c) for the image point x
// relative to the principal point. Only (a, b) set the predicted direction;
// c enters only the optical-axis test. Callers compose any chain of transforms
// (e.g. cam_from_rig * rig_from_world) and pass the result.
//   z = (a, b) / |(a, b)|,  alpha = z^T x,  e = x - max(alpha, 0) z.
// For alpha > 0 this is the usual radial error x - alpha z (|e| is the
// distance of x from the predicted line, |e|^2 = SquaredRadialErrorInCamera).
// For alpha <= 0 x is on the wrong half-line and e = x: the distance from x to
// the nearest point of the predicted half-line, its end at the principal
// point. The residual is thus continuous at alpha = 0 and constant in the pose
// beyond it, so a point that crossed to the wrong side exerts no pull (RANSAC
// rejects such points as outliers beforehand). On the optical axis
// (IsOnOpticalAxis, no direction) e = x too. `point2D` may be a Jet, so the
// principal point can be a parameter.
template <typename T>
void RadialResidual(const T* point2D, const T* point_in_cam, T* residual) {
  residual[0] = point2D[0];
  residual[1] = point2D[1];
  if (IsOnOpticalAxis(point_in_cam)) return;
  const T radial_norm = ceres::sqrt(point_in_cam[0] * point_in_cam[0] +
                                    point_in_cam[1] * point_in_cam[1]);
  const T z0 = point_in_cam[0] / radial_norm;
  const T z1 = point_in_cam[1] / radial_norm;
  const T alpha = z0 * point2D[0] + z1 * point2D[1];
  if (!(alpha > T(0))) return;
  residual[0] -= alpha * z0;
  residual[1] -= alpha * z1;
}

}  // namespace rig_calibrator
