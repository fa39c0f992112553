// Ceres cost functors for the radial reprojection error of a 1D radial camera
// (paper §3.2-3.4): the distance of an observed point, taken relative to the
// principal point, from the half-line on which the camera predicts it.
#pragma once

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace rig_calibrator {

// Radial residual of a camera-frame point with coordinates (a, b, c): only
// (a, b) matter, so callers compose any chain of transforms (e.g.
// cam_from_rig * rig_from_world) and pass the first two coordinates.
//   z = (a, b) / |(a, b)|,  alpha = z^T x,  e = x - max(alpha, 0) z.
// For alpha > 0 this is the usual radial error x - alpha z (|e| is the
// distance of x from the predicted line). For alpha <= 0 x is on the wrong
// half-line and e = x: the distance from x to the nearest point of the
// predicted half-line, its end at the principal point. The residual is thus
// continuous at alpha = 0 and constant in the pose beyond it, so a point that
// crossed to the wrong side exerts no pull (RANSAC rejects such points as
// outliers beforehand). If |(a, b)| < 1e-10 (a point on the optical axis, no
// direction; in world units, far below any map's resolution) e = x too.
// `point2D` may be a Jet, so the principal point can be a parameter.
template <typename T>
void RadialResidual(const T* point2D, const T* point_in_cam, T* residual) {
  const T radial_norm_sq =
      point_in_cam[0] * point_in_cam[0] + point_in_cam[1] * point_in_cam[1];
  residual[0] = point2D[0];
  residual[1] = point2D[1];
  if (radial_norm_sq < T(1e-20)) return;
  const T radial_norm = ceres::sqrt(radial_norm_sq);
  const T z0 = point_in_cam[0] / radial_norm;
  const T z1 = point_in_cam[1] / radial_norm;
  const T alpha = z0 * point2D[0] + z1 * point2D[1];
  if (alpha <= T(0)) return;
  residual[0] -= alpha * z0;
  residual[1] -= alpha * z1;
}

// Radial reprojection error of one 2D-3D correspondence under a
// cam_from_world pose. Parameters: rotation as a unit quaternion
// (w, x, y, z) (use ceres::QuaternionManifold), translation (tx, ty, tz);
// tz does not affect the residual (hold it constant, e.g. with
// ceres::SubsetManifold(3, {2})). Residual: RadialResidual, 2 components.
class RadialReprojectionCost {
 public:
  RadialReprojectionCost(const Eigen::Vector2d& point2D_centered,
                         const Eigen::Vector3d& point3D)
      : point2D_(point2D_centered), point3D_(point3D) {}

  static ceres::CostFunction* Create(const Eigen::Vector2d& point2D_centered,
                                     const Eigen::Vector3d& point3D) {
    return new ceres::AutoDiffCostFunction<RadialReprojectionCost, 2, 4, 3>(
        new RadialReprojectionCost(point2D_centered, point3D));
  }

  template <typename T>
  bool operator()(const T* cam_from_world_rotation,
                  const T* cam_from_world_translation, T* residuals) const {
    const T point3D[3] = {T(point3D_(0)), T(point3D_(1)), T(point3D_(2))};
    T point_in_cam[3];
    ceres::UnitQuaternionRotatePoint(cam_from_world_rotation, point3D,
                                     point_in_cam);
    point_in_cam[0] += cam_from_world_translation[0];
    point_in_cam[1] += cam_from_world_translation[1];
    const T point2D[2] = {T(point2D_(0)), T(point2D_(1))};
    RadialResidual(point2D, point_in_cam, residuals);
    return true;
  }

 private:
  const Eigen::Vector2d point2D_;
  const Eigen::Vector3d point3D_;
};

// Radial residual of one correspondence of camera i in frameset j (the
// radial bundle adjustment's cost), with analytic Jacobians:
//   y = R(q) X + t_q (rig frame),  p = R(a) y + t_a (camera frame),
//   e = RadialResidual(x - c, p)
// for the cam_from_rig (a, t_a) and rig_from_world (q, t_q) parameter blocks
// (angle-axis, translation) and the principal point c. With n = |(p0, p1)|,
// z = (p0, p1) / n and alpha = z^T (x - c) > 0, e = (x - c) - alpha z and
//   de/d(p0, p1) = -(z (x - c)^T + alpha I) (I - z z^T) / n,
//   de/dc = -(I - z z^T);
// otherwise e = x - c, de/dp = 0 and de/dc = -I. Rotations: with J_r the
// right Jacobian of SO(3), R(w + d) = R(w) exp([J_r(w) d]x) to first order, so
// d(R(w) v)/dw = -R(w) [v]x J_r(w). This costs a fraction of automatic
// differentiation, which pushes two angle-axis rotations through
// 14-dimensional jets per residual (radial bundle adjustment of ring5 x 200
// framesets: 4.8 -> 3.0 s, same result).
class RadialRigCostFunction : public ceres::SizedCostFunction<2, 6, 6, 2> {
 public:
  RadialRigCostFunction(const Eigen::Vector2d& point2D,
                        const Eigen::Vector3d& point3D)
      : point2D_(point2D), point3D_(point3D) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const Eigen::Vector2d point2D_;
  const Eigen::Vector3d point3D_;
};

}  // namespace rig_calibrator
