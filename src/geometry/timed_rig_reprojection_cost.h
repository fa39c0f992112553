// The cost of the final bundle adjustment with a time model
// (final_bundle_adjuster.h: unsynchronized cameras, rolling shutter): the
// reprojection error of a map point X observed at pixel x = (x, y) by camera
// c of the rig in frameset f, taken at its own instant
//
//   t = t_f + tau,  tau = delta_c + rho_c (y - 0.5),
//
// delta_c the camera's capture-time offset, rho_c its line delay (seconds
// per row; the row through y = 0.5, the centre of the top row in COLMAP's
// pixel convention, is read first: src/synthetic/capture_model.h uses the
// same convention). The rig pose at t is frameset_motion.h's model,
// rig_from_world(t_f + tau) = M_f(tau)^-1 Q_f, so
//
//   r = pi_theta(P Exp(-u(tau)) (Q X - p(tau))) - x   (pixels),
//
// P = cam_from_rig, Q = rig_from_world of the frameset, theta the camera's
// COLMAP model parameters, [v, a] the frameset's translational velocity
// and acceleration (p1 and p2 of M_f, estimated: frameset_motion.h), M_f's
// other coefficients (u1..3, p3) held: they are given by pointer and the
// adjustment recomputes them between solves.
// The row is the observed y, not the projected one: the two differ by the
// keypoint's noise, whose effect rho_c |dr/dt| |noise| is 10^-3 px and
// below (25 us per row, image motion of 100 px/s, 0.5 px of noise).
//
// Parameter blocks, in order: Q and P as [qw, qx, qy, qz, tx, ty, tz],
// theta (the model's kNumParams), delta_c (1), rho_c (1), [v, a] (6) and, when
// the point is refined, X (3). A block the adjustment does not add (the
// reference camera's delta, which is 0; rho when rolling shutter is off)
// is a constant of the solver.
//
// Jacobians, analytic as in rig_reprojection_cost.h (whose d_pixel/d_cam,
// pose and intrinsics parts they share), with
//   y = R_Q X + t_Q,  w = y - p(tau),  phi = -u(tau),  z = Exp(phi) w,
//   p_cam = R_P z + t_P:
//   dr/d(P)  as there, for the point z,
//   dr/dy    = dr/dz Exp(phi),  dr/dz = dr/dp_cam R_P, and Q and X from dr/dy
//              as there,
//   dr/dtau  = dr/dz Exp(phi) ([w]x Jr(phi) u'(tau) - p'(tau)),
//   dr/ddelta = dr/dtau,  dr/drho = dr/dtau (y_obs - 0.5),
//   dr/dv     = -tau dr/dz Exp(phi),  dr/da = -tau^2/2 dr/dz Exp(phi)
//              (p(tau) = tau v + tau^2/2 a + tau^3/6 p3),
// from d/dtau Exp(phi) = Exp(phi) [Jr(phi) phi']x (Jr the right Jacobian,
// pose_interpolation.h), phi' = -u'(tau), u'(tau) = u1 + tau u2 +
// tau^2/2 u3 and p'(tau) = v + tau a + tau^2/2 p3. Why analytic:
// automatic Jacobians made a timed iteration 4 times a synchronized one
// (docs/benchmarks.md).
// A point that is not in front of the camera is an invalid evaluation.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include "src/geometry/frameset_motion.h"
#include "src/geometry/tangent_jacobian_cost.h"

namespace rig_calibrator {

// r above for the COLMAP model `model_id`, observing `observed`; `point3D`
// fixed, or null for a refined point (the seventh block); `motion` the
// frameset's, read at every evaluation (it must outlive the cost). A
// TangentJacobianCost (the poses in RigPoseManifold's tangent space). Null
// for an unknown model id. The caller owns the result.
ceres::CostFunction* CreateTimedRigReprojectionCost(
    int model_id, const Eigen::Vector2d& observed,
    const Eigen::Vector3d* point3D, const FramesetMotion* motion);

// tau = delta_c + rho_c (y - 0.5): when the row through pixel y is taken,
// relative to t_f (templated for autodiff).
template <typename T>
T CaptureTimeOfRow(const T& time_offset_s, const T& line_delay_s, double y) {
  return time_offset_s + line_delay_s * (y - 0.5);
}

}  // namespace rig_calibrator
