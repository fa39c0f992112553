// Whether a fitted camera model follows the lens over the radii its data
// cover: the mean radial reprojection residual ring by ring.
//
// A model that cannot represent the lens (e.g. OPENCV's
// r_d = r (1 + k1 r^2 + k2 r^4) on a 150-degree fisheye, whose image radius
// grows like the angle theta = atan(r)) is still fitted in the least-squares
// sense: its RMS looks fine, but its residuals are systematic in the radius,
// outwards over some rings and inwards over others, and the observations
// where it cannot follow are rejected as outliers. Such a model passes the
// one-to-one checks (model_validity.h) and is wrong by pixels inside the
// data and by tens of pixels beyond. A model that can represent the lens
// leaves residuals whose mean over any ring is zero up to noise.
//
// Profile: the observations x_k with their projections x^_k, sorted by the
// observed radius r_k = |x_k - c| (c the principal point; points within
// 1 px of c have no radial direction and are left out), cut into
// num_rings = min(max_num_rings, n / min_points_per_ring) rings of equal
// count. Per ring:
//   mean_radial_px = mean_k (x_k - x^_k) . (x_k - c) / r_k
//     (> 0: the lens puts the points farther out than the model),
//   standard_error_px = std_k / sqrt(n_ring),   z = mean / standard error.
// Systematic misfit: a ring with |mean| >= min_bias_px and |z| >= min_z.
// For a model that fits, z is ~N(0, 1) per ring, so min_z = 5 gives false
// alarms below 1e-5 per camera (8 rings x 5.7e-7); the floor min_bias_px
// = 0.25 px keeps the sub-quarter-pixel deviations of a real lens from any
// model family (and the sub-pixel biases of feature detection) from
// counting, however many points there are.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace rig_calibrator {

struct RadialResidualProfileOptions {
  int max_num_rings = 8;
  int min_points_per_ring = 50;  // fewer than 2 rings: not evaluated
  double min_bias_px = 0.25;
  double min_z = 5.0;
};

struct RadialResidualRing {
  double min_radius_px = 0;
  double max_radius_px = 0;
  int num_points = 0;
  double mean_radial_px = 0;
  double standard_error_px = 0;
  double z = 0;  // 0 when the standard error is 0 and the mean too
};

struct RadialResidualProfile {
  bool evaluated = false;  // enough points for two rings
  int num_points = 0;      // used (finite, > 1 px from the principal point)
  std::vector<RadialResidualRing> rings;  // by increasing radius
  bool systematic = false;
  int worst_ring = -1;  // the ring with the largest |z| among the misfits,
                        // else the largest |z|; -1 when not evaluated
};

// `observed` and `projected` pixels (COLMAP convention) of the same
// observations, e.g. a camera's final inliers; non-finite pairs are left out.
RadialResidualProfile ComputeRadialResidualProfile(
    const Eigen::Vector2d& principal_point,
    const std::vector<Eigen::Vector2d>& observed,
    const std::vector<Eigen::Vector2d>& projected,
    const RadialResidualProfileOptions& options =
        RadialResidualProfileOptions());

// For a systematic profile, one clause with the worst ring's numbers, e.g.
// "over radii 198-222 px its 260 inliers sit 0.77 px inwards of the model
// on average (23 standard errors)"; empty otherwise.
std::string DescribeRadialMisfit(const RadialResidualProfile& profile);

}  // namespace rig_calibrator
