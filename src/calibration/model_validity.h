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
//  3. With the data (AddResidualProfileCheck): the final inliers' radial
//     residuals show no systematic misfit ring by ring
//     (radial_residual_profile.h), i.e. the model can follow the lens where
//     there are data. A polynomial on a fisheye lens that does not fold
//     (OPENCV with k2 > 0) fails here: it passes 1 and 2 and is still
//     pixels off inside the data and tens of pixels beyond.
#pragma once

#include <colmap/base/camera.h>

#include <optional>
#include <string>

#include "src/calibration/radial_residual_profile.h"

namespace rig_calibrator {

struct ModelValidityOptions {
  double max_roundtrip_error_px = 0.01;
  int num_rays_per_edge = 32;    // plus the 4 corners
  int num_angle_samples = 2000;  // off-axis angles in (0, 90) degrees
  int grid_step_px = 8;          // of the round-trip grid
  RadialResidualProfileOptions residual_profile;  // of check 3
};

struct ModelValidity {
  bool valid = false;      // monotonic, round trip within the bound and (when
                           // checked) fits_data
  bool monotonic = false;  // check 1 over every ray
  double max_roundtrip_error_px = 0;  // check 2, the worst grid point
  // Smallest pixel radius (from the principal point) at which a ray folds;
  // empty when none does.
  std::optional<double> fold_radius_px;
  // Off-axis angle of the ray at that fold (degrees).
  std::optional<double> fold_angle_deg;
  // Check 3; true when the data were not checked or too few to tell.
  bool fits_data = true;
  std::optional<RadialResidualProfile> residual_profile;
  // Largest distance of an image corner from the principal point.
  double corner_radius_px = 0;
  // For an invalid model: a COLMAP model that can represent the lens
  // (OPENCV_FISHEYE for a pinhole-type model that folds inside the image or
  // that misfits data more than 50 degrees off axis, else the next model
  // with more distortion terms), else empty.
  std::string suggested_model;
  std::string message;  // one sentence, for the diagnostics
};

ModelValidity CheckModelValidity(
    const colmap::Camera& camera,
    const ModelValidityOptions& options = ModelValidityOptions());

// Check 3 on `profile`, the radial residual profile of the camera's final
// inliers: a systematic misfit makes the model invalid, with its numbers in
// the message (which stays the fold's if the model also folds) and a
// suggested model. With `parameters_held` (some intrinsics held at given
// values, --RigCalibrator.refine_*) a misfit may be the given values' and
// says nothing of the model family: fits_data is set, the verdict is left.
void AddResidualProfileCheck(const colmap::Camera& camera,
                             const RadialResidualProfile& profile,
                             bool parameters_held, ModelValidity* validity);

// Whether the model is one of COLMAP's fisheye (angle-based) models.
bool IsFisheyeCameraModel(int model_id);

}  // namespace rig_calibrator
