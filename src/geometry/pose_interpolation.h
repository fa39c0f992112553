// A smooth rigid-body trajectory through timed poses: given world_from_body
// poses T_i = (R_i, c_i) at strictly increasing times t_i (R_i the body's
// orientation in the world, c_i the body origin in world coordinates), the
// pose, angular velocity and linear velocity at any time t.
//
// Scheme (per segment [t_i, t_{i+1}], Delta = t_{i+1} - t_i,
// s = (t - t_i) / Delta, cubic Hermite basis
//   h00 = 2s^3 - 3s^2 + 1, h10 = s^3 - 2s^2 + s,
//   h01 = -2s^3 + 3s^2,    h11 = s^3 - s^2):
//  - position: c(t) = h00 c_i + h10 Delta v_i + h01 c_{i+1} + h11 Delta v_{i+1};
//  - rotation: cubic Hermite in the tangent space at R_i,
//      R(t) = R_i Exp(u(t)),
//      u(t) = h10 Delta w_i + h01 phi + h11 Delta Jr(phi)^-1 w_{i+1},
//    phi = Log(R_i^T R_{i+1}), w_i the body angular velocity at knot i and
//    Jr the right Jacobian of SO(3) (d/dt Exp(u) = Exp(u) [Jr(u) u']x). So
//    R(t_i) = R_i, R(t_{i+1}) = R_{i+1} and the body angular velocity at both
//    ends is w_i, w_{i+1}: the trajectory is C1 (pose and velocities
//    continuous), interpolating, and local (a pose moves only nearby
//    segments).
//  - knot velocities v_i, w_i: the derivative at t_i of the degree <= 4
//    Lagrange polynomial through the (up to) five nearest knots, in the
//    tangent space at R_i for the rotation (points Log(R_i^T R_j)). Its
//    error is O(Delta^4), so the segment's error is the Hermite remainder,
//    O(Delta^4) (Delta^4 / 384 * |x''''| for a scalar).
//
// Class reproduced exactly (to rounding): positions that are polynomials of
// degree <= 3 in t, and rotations R(t) = R_0 Exp(theta(t) a) about a fixed
// axis a with theta a cubic (constant angular velocity about any axis
// included), on any (non-uniform) times with at least four knots (fewer knots
// lower the degree of the knot derivatives).
//
// Why not slerp: linear interpolation of the rotation angle has error
// Delta^2 / 8 * |theta''|. On a rig turning at up to 65 deg/s in a 0.35 Hz
// sway (angular acceleration up to ~1.7 rad/s^2), framesets at 5 Hz
// (Delta = 0.2 s, up to 13 deg apart) give slerp errors up to 0.55 deg, ten
// times a good localization's noise, while this scheme's are 0.004 deg
// (0.016 deg in the two end segments, whose knot derivatives are one-sided);
// positions 0.07 mm against 6.4 mm for linear interpolation at 1.5 m/s
// (measured by PoseTrajectory.FiveHertzErrorOnSmoothTrajectoryIsFarBelowSlerp).
// A cumulative B-spline would be C2 but does not pass through the poses
// (fitting its control points is a nonlinear problem of its own).
//
// Outside [t_0, t_n] the trajectory continues at the end's constant body
// angular velocity and linear velocity (first-order extrapolation, still C1),
// so a caller may evaluate slightly beyond the range while optimizing a time.
//
// Consecutive knots must be less than pi apart in rotation (Log's branch); the
// knot derivatives assume the same of the five-knot stencil.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

// SO(3) tools the interpolation uses, exact to rounding at small angles.
// Exp: rotation vector -> rotation matrix; Log: its inverse on angles < pi.
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& rotation_vector);
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& rotation);
// Jr(u) = I - (1 - cos a)/a^2 [u]x + (a - sin a)/a^3 [u]x^2, a = |u|.
Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& rotation_vector);

class PoseTrajectory {
 public:
  // The state at one time. dR/dt = [angular_velocity_world]x R (so
  // angular_velocity_body = R^T angular_velocity_world), dc/dt = velocity.
  struct State {
    Rigid3d world_from_body;
    Eigen::Vector3d angular_velocity_world = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  };

  // Builds the trajectory. False (with a message naming the problem) if
  // fewer than two poses, sizes differ, times are not finite and strictly
  // increasing, or a pose is not finite.
  static bool Create(const std::vector<double>& times,
                     const std::vector<Rigid3d>& world_from_body,
                     PoseTrajectory* trajectory, std::string* error);

  double StartTime() const { return times_.front(); }
  double EndTime() const { return times_.back(); }
  int NumKnots() const { return static_cast<int>(times_.size()); }

  // The state at time t (extrapolated outside the range, see above).
  State Evaluate(double t) const;

 private:
  State EvaluateSegment(int segment, double t) const;

  std::vector<double> times_;
  std::vector<Eigen::Matrix3d> rotations_;            // R_i, world_from_body
  std::vector<Eigen::Vector3d> positions_;            // c_i
  std::vector<Eigen::Vector3d> body_angular_rates_;   // w_i
  std::vector<Eigen::Vector3d> velocities_;           // v_i
};

// Knots (times strictly increasing, world_from_body poses) cut where two
// consecutive knots are more than max_gap_s apart (a gap the interpolation
// should not bridge), each piece of two knots or more interpolated; a lone
// knot makes no piece.
std::vector<PoseTrajectory> PiecewisePoseTrajectories(
    const std::vector<double>& times_s, const std::vector<Rigid3d>& poses,
    double max_gap_s);

}  // namespace rig_calibrator
