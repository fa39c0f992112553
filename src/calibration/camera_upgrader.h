// Camera upgrade (paper §3.5 "Camera Upgrading and Refinement"):
// from a camera's 1D radial pose (R, tx, ty known, tz unknown) and its 2D-3D
// correspondences, estimate the forward translation tz and all intrinsics of
// a COLMAP camera model.
//
//  1. LO-RANSAC (EstimateRadialIntrinsicsRansac,
//     src/estimators/radial_intrinsics_estimator.h) for the target model's
//     radial profile (polynomial for the perspective models, equidistant for
//     the fisheye ones) with f and the first two radial terms: hypotheses
//     from the minimal solver (SolveMinimalRadialIntrinsics, closed form),
//     local optimization by variable projection over tz
//     (SolveRadialIntrinsicsLeastSquares). With the focal length held, both
//     take it as known (tz and the radial terms only). Residual: full
//     reprojection error, principal point fixed at the input estimate.
//  2. Conversion to the model's parameters: fx = fy = f, k1, k2 where the
//     model has them, every other distortion term 0.
//  3. Levenberg-Marquardt (Ceres, Cauchy loss) over tz and all parameters of
//     the model (the principal point too unless told otherwise) on the full
//     reprojection error through COLMAP's templated WorldToImage, on the
//     inliers or an even subsample of at most max_num_refinement_points of
//     them, then the inliers are re-evaluated on all points; repeated while
//     they change (at most 3 times).
//
// Used for each rig camera with its frames pooled and, for the `rd`
// baseline, for single images.
#pragma once

#include <colmap/base/camera.h>

#include <Eigen/Core>
#include <string>
#include <vector>

namespace rig_calibrator {

struct CameraUpgradeOptions {
  double max_error_px = 10.0;  // RANSAC inlier threshold on the full
                               // reprojection error; also the final inliers
  double confidence = 0.9999;
  int min_num_trials = 50;
  int max_num_trials = 2000;
  // RANSAC runs on a random subset of at most this many correspondences (a
  // camera pooled over hundreds of frames has 1e5 of them); the inliers are
  // then evaluated on all of them.
  int max_num_ransac_points = 10000;
  // Each round of the final LM runs on at most this many of the inliers,
  // evenly spaced in index order (of n, the floor(j n / m)-th for j < m =
  // min(n, max)): a camera pooled over hundreds of frames has 1e5 of them,
  // the LM's cost grows with their number, and a dozen parameters gain little
  // from more. The inliers are then re-evaluated on all correspondences, and
  // the conditioning below is that of all the inliers. Must be at least the
  // number of unknowns (tz and the refined parameters). At 10000, the model
  // choice's candidates, fitted on at most as many rows
  // (ModelSelectionOptions::max_num_fit_rows), use all their inliers: only
  // the chosen model's fit to every row is subsampled.
  int max_num_refinement_points = 10000;
  double loss_scale_px = 1.0;  // Cauchy scale in the final LM
  int max_num_iterations = 100;
  // COLMAP's refine_* switches (intrinsics_refinement.h): a parameter not
  // refined keeps the input camera's value. With the focal length held the
  // RANSAC's minimal solver, its local optimization and their polish all use
  // the given f (its mean fx, fy for a model with two), so the inliers, tz
  // and the distortion that start the LM are those of that f, and the LM
  // estimates tz and the distortion. With the extra parameters held, the LM
  // starts from and keeps the given distortion.
  bool refine_principal_point = true;
  bool refine_focal_length = true;
  bool refine_extra_params = true;
  int num_threads = 1;  // of the LM; <= 0: all cores
};

struct CameraUpgradeResult {
  double tz = 0;  // forward translation to add to the camera-frame points
  std::vector<char> inlier_mask;  // per input correspondence
  int num_inliers = 0;
  double rms_px = 0;  // full reprojection RMS over the inliers

  // Conditioning of the tz/focal trade-off. With
  // C = (J^T J)^-1, J the (Cauchy-weighted) Jacobian of the final LM's
  // residuals in pixels over tz and every refined parameter (of all that
  // round's inliers: from its subsample of m of the n, C is scaled by m / n),
  // and f the mean of the model's focal lengths:
  //   tz_focal_correlation = C(tz, f) / sqrt(C(tz, tz) C(f, f)).
  // It tends to 1 when the depths of the points vary little relative to
  // their distance, since then only f / (c + tz) is observed; 1 when J^T J is
  // numerically singular.
  double tz_focal_correlation = 0;
  // One-sigma uncertainties sqrt(C(tz, tz)) and sqrt(C(f, f)) for a pixel
  // noise of 1 px (multiply by rms_px for the observed noise); 0 when J^T J
  // is numerically singular.
  double tz_stddev_at_1px = 0;
  double focal_stddev_at_1px = 0;
  // False when J^T J is numerically singular, focal_stddev_at_1px >
  // kMaxRelativeStddevAt1px f, or tz_stddev_at_1px > kMaxRelativeStddevAt1px
  // times the median depth of the inliers: f or tz is then poorly determined
  // (too little depth variation, too few points or too narrow a view).
  bool well_conditioned = false;

  std::string error_message;  // why UpgradeCamera returned false
};

// Largest relative uncertainty of f and tz (at 1 px noise) of a well
// conditioned upgrade.
constexpr double kMaxRelativeStddevAt1px = 0.01;

// Whether UpgradeCamera supports the COLMAP camera model: SIMPLE_PINHOLE,
// PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV, SIMPLE_RADIAL_FISHEYE,
// RADIAL_FISHEYE, OPENCV_FISHEYE, THIN_PRISM_FISHEYE (not FOV).
bool IsUpgradeSupportedCameraModel(int model_id);

// points2D: pixels (COLMAP convention). points_cam: camera-frame points
// WITHOUT tz, i.e. R X + (tx, ty, 0), on the correct half-line of the radial
// pose. camera: in: model_id, width, height, params (principal point = the
// current estimate, e.g. from the radial BA; the focal length and extra
// params are used only when held, see the options); out: all params of that
// model. Correspondences with non-finite values are outliers.
// Returns false (camera unchanged, result->error_message set and logged) for
// bad input, an unsupported model or when no consistent model is found.
bool UpgradeCamera(const CameraUpgradeOptions& options,
                   const std::vector<Eigen::Vector2d>& points2D,
                   const std::vector<Eigen::Vector3d>& points_cam,
                   colmap::Camera* camera, CameraUpgradeResult* result);

}  // namespace rig_calibrator
