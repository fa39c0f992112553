// The uncertainty of a calibration (pipeline step 7): the standard deviation
// of every estimated intrinsic parameter, of every camera's cam_from_rig and
// of its centre in the rig, and per camera the 1-sigma projection
// uncertainty over the image, from the final bundle adjustment's own
// problem (final_bundle_adjuster.h) at its result.
//
// Model. The final adjustment minimizes sum_i rho(|r_i|^2) over the inlier
// observations i (rig images and, with map observations, map images), r_i
// the reprojection error of RigReprojectionCost, rho the Cauchy loss. With
// J the Jacobian of all r_i over every free parameter (tangent spaces:
// rotations as rotation vectors applied on the left, R' = Exp(w) R), the
// covariance of an M-estimate with independent, identically distributed,
// isotropic 2D residuals is (Huber, Robust Statistics, 1981, sec. 7.6)
//
//   Cov = sigma_eff^2 (J^T J)^-1,
//   sigma_eff^2 = m/(m-p) * mean(rho'(s)^2 s/2) / mean(rho'(s) + s rho''(s))^2,
//
// s_i = |r_i|^2, m the number of residual components (2 per observation), p
// the number of free parameters less the gauge's (m/(m-p): the residuals at
// the estimate are smaller than the noise by that factor, exactly for a
// linear Gaussian model). Without loss (rho(s) = s) sigma_eff^2 is the
// unbiased residual variance sum |r|^2 / (m - p), the `residual_scale_px`
// reported. The rig poses, the refined map points and (refine_map) the map
// images' poses and intrinsics are nuisance parameters: they are
// marginalized (points by their 3x3 blocks, then the rig and map poses by a
// sparse Cholesky factorization of the reduced system), leaving the
// covariance of the intrinsics and cam_from_rig of the rig cameras.
//
// The reduced system is the solver's. The adjustment's problem (its cost
// functions over the observations above, its parameter blocks and
// manifolds, its refined points) is registered with the own Levenberg-
// Marquardt solver, whichever backend ran the adjustment, and its
// Gauss-Newton reduced system taken at the result
// (BundleLevenbergMarquardt::LinearizeGaussNewton: J^T J without loss or
// damping, the points eliminated by the step's own code, V_p^+ for a point
// without information along a direction); the anchoring and the
// between-framesets scores move point-side vectors with its
// EliminatePointVector and BackSubstitutePoint. Its pose coordinates are
// RigPoseManifold's (d, t), R' = Exp(2 d) R: the covariance is computed in
// them and reported in (w, t), w = 2 d.
//
// Time model. When ba_options has one (estimate_time_offsets /
// estimate_line_delays, their values in initial_time_offsets_s /
// initial_line_delays_s: the result's), the rig observations are the
// adjustment's timed ones (timed_rig_reprojection_cost.h, the frameset
// motions from the result's rig poses, held as in the adjustment), and the
// estimated offsets and line delays are parameters of C, in their camera's
// block: their sigmas come out of the same marginalization, covering the
// map, the rig poses and the intrinsics they trade off against.
//
// Gauge. The reference camera's cam_from_rig is the identity and has no
// uncertainty. Fixed map points (refine_points off, or points seen once) or
// fixed map images (refine_map off) fix the world frame and scale, and the
// covariance is the inverse above. When nothing is fixed (refine_map, the
// default, or every point refined), the world has 7 free degrees of freedom
// (a similarity) and the adjuster moves its result onto the map by the
// similarity that aligns the adjusted map camera centres (or refined points)
// with the input ones (map_anchoring.h). Intrinsics and cam_from_rig
// rotations do not change under a similarity; the cam_from_rig translations
// scale with it, so their uncertainty includes that of the scale the
// anchoring picks. To first order the anchored result is
//   d_C' = d_C - n_C g(d),  g(d) = sum_k (c_k - c_mean).d c_k / sum_k |c_k -
//   c_mean|^2,
// n_C the translations of cam_from_rig (the scale direction), c_k the anchor
// centres (or points). Its covariance L Cov L^T, L = [I, -n_C g], is the same
// for any choice of gauge made to compute Cov (L annihilates the gauge
// directions), so the computation holds the gauge by priors on one rig pose
// and on the scale, and then applies L.
//
// Projection uncertainty (as mrcal's): for the centre q of every cell of a
// grid over the image, the point p at distance `depth` along the estimated
// ray through q (unprojected with the estimated intrinsics) is held fixed in
// the rig frame; its projection q(theta, P) = pi_theta(P p) then moves with
// the intrinsics theta and cam_from_rig P only, and Cov_q = J Cov_(theta,P)
// J^T, J = dq/d(theta, P). Reported: sqrt of the larger eigenvalue of Cov_q
// (the standard deviation in the worst direction), pixels. `depth` is the
// median distance of the camera's inlier observations (map units): the
// distances at which the calibration was measured. For the reference camera
// only the intrinsics move.
//
// Between framesets. The covariance above is exact for independent noise
// of one level; real residuals are neither. A real map has errors that
// every observation of one image or one frameset shares (its pose in the
// map, the map's distortion where the image sees it, a frameset's timing),
// and cameras differ in noise. The real 5-camera ring's per-timestamp rig
// scatters by 0.2-0.6 deg in its own map, while the covariance above gave
// 0.01-0.02 deg. So a second estimate is made, from the spread of the data
// between framesets (a cluster-robust sandwich, Liang & Zeger 1986; to
// first order the jackknife over framesets): each frameset's rig images
// (and each map image) form a cluster g with score s_g = sum_{k in g}
// rho'(s_k) J_k^T r_k, its influence on the estimate is
// d_g = (J^T J)^-1 s_g / mean(rho' + s rho''), and
//   Cov_between = G/(G-1) sum_g d_g d_g^T
// (G clusters; with G < 3 it is not computed). It includes per-camera noise
// levels and every error that differs between framesets, without
// assuming a model for them; it is noisier than the first (G-1 degrees of
// freedom). Every reported standard deviation (parameters, rotation,
// centre, each projection cell) is the larger of the two, and per camera
// `between_framesets_factor` says how much larger the second is at most.
//
// What neither covers: errors that every frameset shares, e.g. fixed map
// points or fixed map poses that are wrong the same way for all framesets
// (a map's drift or scale across the whole area), or a camera model that
// cannot represent the lens the same way in every image (the model checks,
// model_validity.h, look for that). Undetermined parameters (a singular
// reduced system) are reported as undetermined, never as a number.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace rig_calibrator {

// Declared here, defined in final_bundle_adjuster.h, pipeline_report.h and
// src/rig/rig_dataset.h, so that the pipeline's report can hold the result
// structs below.
struct FinalBundleAdjustmentOptions;
struct RigDataset;
struct RigCalibration;
struct Diagnostic;

struct UncertaintyOptions {
  // Columns of the projection grid; rows = round(cols * height / width).
  int grid_cols = 16;
};

// The 1-sigma projection uncertainty over a camera's image.
struct ProjectionUncertainty {
  int cols = 0, rows = 0;
  // Per cell (row-major), at the cell centre, pixels; NaN where the
  // estimated model does not unproject the pixel (round trip off by more
  // than 0.01 px).
  std::vector<double> stddev_px;
  double depth = 0;  // map units (see the top of the file)
  // Over the cells with a value.
  double median_px = 0, max_px = 0;
  Eigen::Vector2d max_at = Eigen::Vector2d::Zero();  // cell centre, pixels
};

struct CameraUncertainty {
  // False: the camera is not calibrated or takes no part in the adjustment.
  bool computed = false;
  // False: some parameter is not determined by the data (singular reduced
  // system); its standard deviation is NaN, and the projection grid is not
  // computed.
  bool determined = false;
  // One per model parameter (COLMAP order): 0 for a parameter held fixed,
  // NaN when undetermined. After the pipeline's uncertainty stage, the
  // larger of the adjustment's and the model choice's spread
  // (model_choice_spread.h).
  std::vector<double> params_stddev;
  // That spread, one per parameter, where it is the larger (0 elsewhere);
  // empty when it is nowhere (the choice on the adjusted rig did not run,
  // found no other candidate as good as the best, or the adjustment's
  // sigmas are larger).
  std::vector<double> model_choice_stddev;
  // cam_from_rig: the rotation vector w of R' = Exp(w) R (camera frame) per
  // axis and sqrt(trace Cov_w) (the RMS rotation angle), degrees; the
  // translation per axis and the camera centre in the rig (-R^T t) per axis,
  // map units. Zero for the reference camera.
  Eigen::Vector3d rotation_axis_stddev_deg = Eigen::Vector3d::Zero();
  double rotation_stddev_deg = 0;
  Eigen::Vector3d translation_stddev = Eigen::Vector3d::Zero();
  Eigen::Vector3d center_in_rig_stddev = Eigen::Vector3d::Zero();
  // Covariance over [params (all, in order), w (3), t (3)] (fixed: rows and
  // columns of zeros): from the noise level (see the top), and between
  // framesets (empty when not computed). The standard deviations above are
  // the larger of the two.
  Eigen::MatrixXd covariance;
  Eigen::MatrixXd between_framesets_covariance;
  // max over the free parameters of sigma_between / sigma_noise (0 when not
  // computed): above ~1.5 the framesets disagree more than the pixel noise
  // explains, and the between-framesets sigma is the one reported.
  double between_framesets_factor = 0;
  // With the final adjustment's time model (final_bundle_adjuster.h): the
  // standard deviations of the capture-time offset (seconds) and the line
  // delay (seconds per row), the larger of the two estimates; 0 when not
  // estimated, NaN when undetermined. Not in `covariance`.
  double time_offset_stddev_s = 0;
  double line_delay_stddev_s = 0;
  ProjectionUncertainty projection;
};

struct CalibrationUncertainty {
  bool computed = false;
  std::string message;  // why not computed, or what is undetermined
  // The unbiased residual standard deviation of one pixel coordinate
  // (sqrt(sum |r|^2 / (m - p))) and sigma_eff (see the top of the file).
  double residual_scale_px = 0;
  double effective_scale_px = 0;
  int64_t num_residuals = 0;   // m
  int64_t num_parameters = 0;  // p (free, less the gauge)
  bool free_gauge = false;     // anchored by a similarity (see the top)
  int num_clusters = 0;  // of the between-framesets covariance (0: none)
  // What was marginalized and how the gauge was handled, in words.
  std::string method;
  double seconds = 0;
  std::vector<CameraUncertainty> cameras;  // per dataset camera
};

// The uncertainty of `calibration`, the result of AdjustRig(ba_options,
// dataset, ...): the same observations (the inlier masks, the map
// observations of refined points not rejected), free parameters and gauge.
// Never NaN where a number is reported; `computed` false with a message when
// the problem has no redundancy or its reduced system cannot be factored.
CalibrationUncertainty EstimateCalibrationUncertainty(
    const FinalBundleAdjustmentOptions& ba_options, const RigDataset& dataset,
    const RigCalibration& calibration,
    const UncertaintyOptions& options = UncertaintyOptions());

// Thresholds of the diagnostics (why these values: calibration_uncertainty.cc).
constexpr double kLargeProjectionStddevPx = 1.0;
constexpr double kPoorPrincipalPointStddevPx = 1.0;
constexpr double kFramesetsDisagreeFactor = 3.0;

// The warnings "large_projection_uncertainty" (a camera's worst projection
// standard deviation above kLargeProjectionStddevPx), "poorly_determined_
// principal_point" (a principal point coordinate's standard deviation above
// kPoorPrincipalPointStddevPx, or undetermined: suggests
// --RigCalibrator.refine_principal_point 0; says so when the model choice's
// spread, model_choice_stddev, is what puts it there), "framesets_disagree" (a
// camera's between_framesets_factor above kFramesetsDisagreeFactor) and
// "undetermined_parameters".
std::vector<Diagnostic> UncertaintyDiagnostics(
    const RigDataset& dataset, const RigCalibration& calibration,
    const CalibrationUncertainty& uncertainty);

}  // namespace rig_calibrator
