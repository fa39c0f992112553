// A closed walk on the ground: the ellipse
//   p(phi) = center + (a cos phi, b sin phi),   phi in [0, 2 pi),
// travelled at constant speed, so that the arc length s is the natural
// parameter. The synthetic trajectory (rig_trajectory.h) walks it when a
// rendered scene bounds where the rig may go (rendered_dataset.h).
// Internal to the synthetic data generator.
//
// The arc length S(phi) = integral_0^phi |p'(u)| du, |p'(u)| =
// sqrt(a^2 sin^2 u + b^2 cos^2 u), has no closed form (an elliptic
// integral); it is tabulated at kKnots knots (5-point Gauss-Legendre per
// interval, exact to rounding for this smooth integrand) and inverted by
// cubic Hermite interpolation of phi(s) with the exact slopes dphi/ds =
// 1 / |p'(phi)| at the knots: phi(s) is C1, its derivative is the
// interpolant's, and the speed |dp/ds| is 1 to about 1e-8
// (the interpolation's h^3 on the street's thin ellipse).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace rig_calibrator {

class GroundLoop {
 public:
  // radii (a, b) > 0; the walk starts (s = 0) at phi = start_angle and goes
  // counter-clockwise (phi increasing).
  GroundLoop(const Eigen::Vector2d& center, const Eigen::Vector2d& radii,
             double start_angle);

  // The ellipse parameter phi at arc length s (any s, also negative or
  // beyond a lap; phi grows by 2 pi a lap) and dphi/ds there.
  double AngleAt(double arc_length, double* angle_rate_per_m) const;
  // p(phi) and p'(phi) = dp/dphi.
  Eigen::Vector2d PointAt(double angle) const;
  Eigen::Vector2d TangentAt(double angle) const;
  // The length of a lap and max_phi dphi/ds = 1 / min(a, b).
  double Perimeter() const { return knot_lengths_.back(); }
  double MaxAngleRatePerMeter() const { return 1 / radii_.minCoeff(); }

 private:
  static constexpr int kKnots = 4096;
  Eigen::Vector2d center_, radii_;
  double start_angle_ = 0;
  // S at phi_k = start_angle + 2 pi k / kKnots, k = 0 .. kKnots.
  std::vector<double> knot_lengths_;
};

}  // namespace rig_calibrator
