// Whether a fitted COLMAP camera model is valid over the whole image: the
// projection is one-to-one from the principal point out to every pixel of
// the image, and COLMAP's undistortion (ImageToWorld) inverts it.
//
// A polynomial distortion fitted to the inner part of a wide lens (e.g.
// OPENCV with a strong negative k2 on a fisheye) reaches a largest radius and
// then folds back: pixels beyond that radius have no ray, pixels inside it
// have several, and COLMAP's iterative undistortion converges to a wrong one.
// The fit itself can look excellent (its inliers are inside the fold).
//
// Checks, on the map (u, v) -> pixel of the normalized image plane (COLMAP's
// WorldToImage):
//  1. Along rays from the principal point to points of the image border
//     (the 4 corners and points on every edge), sampled finely in the
//     off-axis angle theta (u, v) = tan(theta) d: until the ray's pixel
//     leaves the image, its distance from the principal point must grow,
//     r(theta_k+1) > r(theta_k), and the Jacobian J = d pixel / d(u, v)
//     (central differences) must keep det J > 0, which also catches folds of
//     the tangential / thin-prism terms. The first violation on a ray is a
//     fold; its pixel radius is reported.
//  2. Round trip: every point of a grid over the whole image (cell centres,
//     edges and corners), ImageToWorld then WorldToImage, must come back
//     within max_roundtrip_error_px (COLMAP's own functions).
#pragma once

#include <colmap/base/camera.h>

#include <optional>
#include <string>

namespace rig_calibrator {

struct ModelValidityOptions {
  double max_roundtrip_error_px = 0.01;
  int num_rays_per_edge = 32;    // plus the 4 corners
  int num_angle_samples = 2000;  // off-axis angles in (0, 90) degrees
  int grid_step_px = 8;          // of the round-trip grid
};

struct ModelValidity {
  bool valid = false;      // monotonic and round trip within the bound
  bool monotonic = false;  // check 1 over every ray
  double max_roundtrip_error_px = 0;  // check 2, the worst grid point
  // Smallest pixel radius (from the principal point) at which a ray folds;
  // empty when none does.
  std::optional<double> fold_radius_px;
  // Off-axis angle of the ray at that fold (degrees).
  std::optional<double> fold_angle_deg;
  // Largest distance of an image corner from the principal point.
  double corner_radius_px = 0;
  // For an invalid model: a COLMAP model that can represent the lens
  // (OPENCV_FISHEYE for a pinhole-type model that folds inside the image),
  // else empty.
  std::string suggested_model;
  std::string message;  // one sentence, for the diagnostics
};

ModelValidity CheckModelValidity(
    const colmap::Camera& camera,
    const ModelValidityOptions& options = ModelValidityOptions());

// Whether the model is one of COLMAP's fisheye (angle-based) models.
bool IsFisheyeCameraModel(int model_id);

}  // namespace rig_calibrator
