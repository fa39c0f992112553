// The model the camera upgrade estimates (paper §3.5): the
// forward translation tz, the focal length and the first radial distortion
// terms of a camera whose 1D radial pose (R, tx, ty) is known.
//
// Notation shared by the upgrade solvers: x = (u, v) is a pixel relative to
// the principal point, rho = |x|. (a, b, c) = R X + (tx, ty, 0) is the
// camera-frame point without tz, so the full camera-frame point is
// (a, b, c + tz). s = x.(a, b) / rho is the signed radial coordinate of the
// 3D point along the image point's direction; s > 0 for a point on the
// correct half-line of the radial pose.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace rig_calibrator {

// How the distance of an image point from the principal point depends on the
// incoming ray's angle theta to the optical axis.
enum class RadialProfile {
  // r_d = f q (1 + k1 q^2 + k2 q^4), q = tan(theta): the radial part of
  // SIMPLE_RADIAL, RADIAL, OPENCV and FULL_OPENCV (k3.. and tangential = 0).
  kPolynomial,
  // r_d = f theta (1 + k1 theta^2 + k2 theta^4): the OpenCV fisheye family
  // (SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE, OPENCV_FISHEYE, k3.. = 0).
  kEquidistant,
};

// tz, focal length and the first `num_radial_terms` (0..2) distortion terms
// of a radial profile.
struct RadialIntrinsics {
  RadialProfile profile = RadialProfile::kPolynomial;
  int num_radial_terms = 0;
  double tz = 0;
  double focal = 0;
  double k[2] = {0, 0};

  // Radial distance r_d of the image of a ray with tan(theta) = q >= 0.
  double DistortedRadius(double q) const;

  // Image of the camera-frame point (a, b, c + tz) relative to the principal
  // point; false when c + tz <= 0 (behind the camera, or on its plane).
  bool Project(const Eigen::Vector3d& point_cam, Eigen::Vector2d* x) const;
};

// s = x.(a, b) / |x|; 0 for a pixel on the principal point, which carries no
// radial information.
double SignedRadialCoordinate(const Eigen::Vector2d& x,
                              const Eigen::Vector3d& point_cam);

// The profile's angle variable phi of a ray with radial coordinate s at depth
// c + tz: phi = s / depth (polynomial) or atan2(s, depth) (equidistant), so
// that r_d = f (phi + k1 phi^3 + k2 phi^5). An odd function of s: a point on
// the wrong half-line (s < 0) predicts a negative radius.
double ProfileAngle(RadialProfile profile, double s, double depth);

// Whether r_d grows with the ray angle over the angles of the points:
// d r_d / d phi = f (1 + 3 k1 phi^2 + 5 k2 phi^4) > 0 for phi in [0, max_phi],
// max_phi the largest |phi| of the points. A profile that folds back can fit
// points on the wrong half-line (a negative 1 + k1 phi^2 + k2 phi^4 mirrors
// them through the principal point) and is not a lens.
bool RadiusGrowsOverPoints(const std::vector<Eigen::Vector2d>& x,
                           const std::vector<Eigen::Vector3d>& points_cam,
                           const RadialIntrinsics& model);

}  // namespace rig_calibrator
