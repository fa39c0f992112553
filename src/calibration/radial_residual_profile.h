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
//   z = mean / standard_error_px.
// The standard error is clustered by image (the "group" of an observation):
//   SE^2 = G/(G-1) sum_g (sum_{k in g} (e_k - mean))^2 / n_ring^2,
// G the images with observations in the ring. Why: the residuals of a real
// map are not independent. Every observation of one image shares that
// image's error in the map (its pose, the map's distortion where it was
// triangulated), so a ring's residuals move together image by image; with
// the per-observation standard error (std / sqrt(n), what this formula
// gives with one observation per group) the real 5-camera ring's own model
// came out 5-13 standard errors off. The clustered one measures the spread
// between images, which includes those errors; a lens that the model cannot
// follow is off the same way in every image and stays many standard errors
// off. With one group per observation it is the usual std / sqrt(n).
//
// Systematic misfit: a ring with |mean| >= min_bias_px and |z| beyond the
// threshold. For a model that fits, z follows Student's t with G-1 degrees
// of freedom (a normal when G is large); the threshold is the t quantile of
// the same two-sided tail probability as min_z standard deviations of a
// normal (min_z = 4: 6.3e-5 per ring, false alarms below 1e-3 per camera),
// so few images need a larger z (6.2 for 12 images, 7.6 for 9, 17 for 5). The floor
// min_bias_px = 0.25 px keeps the sub-quarter-pixel deviations of a real
// lens from any model family (and the sub-pixel biases of feature
// detection) from counting, however many points there are. Where the data
// themselves carry a systematic level (systematic_floor_px: the map's own,
// camera_model_stage.h), a ring must exceed it significantly:
// (|mean| - floor) / SE beyond the threshold.
#pragma once

// First: COLMAP's std::vector<Eigen::Vector2d> specialization (its aligned
// allocator) must precede any use of that vector type, here and in the
// files that include this header.
#include <colmap/util/types.h>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace rig_calibrator {

struct RadialResidualProfileOptions {
  int max_num_rings = 8;
  int min_points_per_ring = 50;  // fewer than 2 rings: not evaluated
  double min_bias_px = 0.25;
  double min_z = 4.0;
  // A systematic level that the data carry whatever the model (the map's
  // own; camera_model_stage.h): a ring is a misfit only when its |mean|
  // exceeds it by the threshold's standard errors, (|mean| - floor) / SE.
  double systematic_floor_px = 0;
};

struct RadialResidualRing {
  double min_radius_px = 0;
  double max_radius_px = 0;
  int num_points = 0;
  double mean_radial_px = 0;
  double standard_error_px = 0;  // clustered by image (see the top)
  int num_groups = 0;             // images with observations in the ring
  double z = 0;  // 0 when the standard error is 0 and the mean too
  double z_threshold = 0;  // |z| beyond this (and the floor): systematic
};

struct RadialResidualProfile {
  bool evaluated = false;  // enough points for two rings
  int num_points = 0;      // used (finite, > 1 px from the principal point)
  std::vector<RadialResidualRing> rings;  // by increasing radius
  bool systematic = false;
  double systematic_floor_px = 0;  // the one the rings were judged with
  int worst_ring = -1;  // the ring with the largest |z| among the misfits,
                        // else the largest |z|; -1 when not evaluated
};

// `observed` and `projected` pixels (COLMAP convention) of the same
// observations, e.g. a camera's final inliers; non-finite pairs are left out.
// `groups`: the image (any integer id) of every observation, the clusters of
// the standard error; empty: every observation its own group.
RadialResidualProfile ComputeRadialResidualProfile(
    const Eigen::Vector2d& principal_point,
    const std::vector<Eigen::Vector2d>& observed,
    const std::vector<Eigen::Vector2d>& projected,
    const std::vector<int>& groups = {},
    const RadialResidualProfileOptions& options =
        RadialResidualProfileOptions());

// The |t| of Student's t with `degrees_of_freedom` whose two-sided tail
// probability is that of `normal_z` standard deviations of a normal.
double StudentThresholdLikeNormal(double normal_z, int degrees_of_freedom);

// For a systematic profile, one clause with the worst ring's numbers, e.g.
// "over radii 198-222 px its 260 inliers sit 0.77 px inwards of the model
// on average (23 standard errors)"; empty otherwise.
std::string DescribeRadialMisfit(const RadialResidualProfile& profile);

}  // namespace rig_calibrator
