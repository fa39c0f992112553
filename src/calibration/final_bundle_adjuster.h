// Final bundle adjustment of the rig calibration (paper §3.6, pipeline step 6):
// all intrinsics, every camera's cam_from_rig and every frameset's
// rig_from_world are refined together on the full reprojection error
//
//   min  sum_{i,j,p} rho(|pi_theta_i(P_i Q_j X_p) - x_ijp|^2),
//
// theta_i the COLMAP camera model parameters of camera i, P_i its
// cam_from_rig, Q_j the rig_from_world of frameset j, X_p a map point, rho the
// Cauchy loss (the cost of one observation:
// src/geometry/rig_reprojection_cost.h). Map points are held fixed unless asked
// (they fix the world frame and scale); the reference camera's cam_from_rig
// stays the identity (it defines the rig frame). After a first solve, outliers
// are pruned relative to each camera's robust residual spread and the problem
// is solved again.
//
// Time model (estimate_time_offsets / estimate_line_delays, needs the
// dataset's frameset times): each rig observation of camera c in frameset f
// is taken at its own instant t_f + delta_c + rho_c (y - 0.5) and uses the
// rig pose at that instant, rig_from_world(t_f + tau) = M_f(tau)^-1 Q_f, the
// rig's motion M_f around t_f to third order in tau (frameset_motion.h:
// why this form and order), its coefficients from the current rig poses,
// held within a solve and recomputed before each (the cost:
// timed_rig_reprojection_cost.h), except the translational velocity and
// acceleration [v_f, a_f]: parameters of each frameset, in its pose's block
// row, with a prior towards the polynomial's, evaluated from the poses
// inside the solve (translation_prior_cost.h), because the images see them
// and the frameset poses do not follow a motion faster than a fraction of
// their rate (a walk's bob at 5 Hz, a car's vibration at 15 Hz).
// delta_c are refined for the non-reference
// cameras (delta_ref = 0 defines the rig's clock), rho_c for every camera
// (a rolling shutter's line delay is observable for the reference camera
// too). After the last solve the motion is recomputed once more and the
// problem solved again, so that the result is a fixed point of the model.
// The time parameters are in their camera's block row of the reduced system
// (with its intrinsics and cam_from_rig), on either backend; their sigmas
// are the calibration's uncertainty's (calibration_uncertainty.h).
//
// Solver: the problem's own Levenberg-Marquardt
// (src/solvers/bundle_levenberg_marquardt.h), which eliminates the refined
// points by their 3 x 3 blocks and factorizes the reduced system over the rig
// poses, map poses and cameras (a camera's cam_from_rig and intrinsics one
// block) with a sparse Cholesky; it uses every thread and its result does
// not depend on their count. Or Ceres', to compare with (bundle_solver).
#pragma once

#include <string>
#include <vector>

#include "src/rig/rig_dataset.h"
#include "src/solvers/bundle_solver.h"

namespace rig_calibrator {

// AdjustRig stops its last solve when an iteration lowers the cost by less than
// this share of it (Ceres' default 1e-6). With refined map points the last
// iterations only polish tens of thousands of points along the Cauchy loss'
// flat tail: 500 framesets x 10 cameras, 1e-5 -> 1e-4 ends the last solve after
// 2 iterations instead of 7 (the final BA 13 -> 8 iterations) with the same
// errors against the truth (0.0185 -> 0.0183 deg, 0.50 mm);
// exact data still converge to 1e-8 (each step there lowers the cost by
// most of it).
inline constexpr double kFinalBundleAdjustmentFunctionTolerance = 1e-4;

struct FinalBundleAdjustmentOptions {
  double loss_scale_px = 1.0;  // Cauchy loss scale
  int max_num_iterations = 100;
  bool refine_focal_length = true;  // false for the `known` method
  bool refine_principal_point = true;
  bool refine_extra_params = true;  // distortion
  // cam_from_rig of the non-reference cameras (the reference camera is held
  // at the identity).
  bool refine_extrinsics = true;
  bool refine_rig_poses = true;  // rig_from_world
  // Map points (by point3D_id). Only points with an id that are observed at
  // least twice are refined: a point seen once has 3 unknowns for 2
  // residuals, and points with id -1 are a separate point per observation.
  // The points that stay fixed anchor the world frame and scale, and the
  // solution is left where they hold it. Only when every observed point is
  // refined (nothing fixes the gauge) is the result moved back onto the map
  // by the similarity that best aligns the refined points with their map
  // positions, which changes no reprojection error (map_anchoring.h).
  bool refine_points = false;
  // With refine_points and map images in the dataset: the map images'
  // observations of the refined points are residuals as well, with the same
  // robust loss and outlier pruning (thresholds per map camera), so that a
  // point's position uses all the images that see it. The map images' poses
  // and intrinsics are held fixed and anchor the world frame and scale; a
  // point is then refined when the rig images observe it and it has at
  // least two observations in all. Pruned map observations are reported
  // (RigCalibration::map_observation_rejected). Without it (false), the map
  // images take no part in the solve, but their observations of refined
  // points are checked after it with the same rule, so that those that no
  // longer fit are reported as rejected too.
  bool use_map_observations = true;
  // Needs refine_points and map images: the map is adjusted with the rig,
  // every map image's pose and every map point with two observations or
  // more (refine_map_intrinsics: the map cameras' focal lengths, principal
  // points and distortion too). Nothing then holds the gauge, and the
  // solution is moved onto the map by the similarity that best aligns the
  // adjusted map camera centres with the input ones (map_anchoring.h).
  bool refine_map = false;
  bool refine_map_intrinsics = false;
  // Outlier pruning after a first solve, then solve again. An observation is
  // an outlier if
  //  - its reprojection error exceeds max(min_outlier_error_px,
  //    outlier_sigma_factor * sigma_i), sigma_i = 1.4826 * MAD of the x and y
  //    residual components of its camera i (the robust standard deviation of
  //    one component; for Gaussian noise |e| > 4 sigma has probability
  //    exp(-8)). The sigma is per camera so that a fisheye camera, whose
  //    periphery has larger but consistent errors, keeps its periphery while a
  //    pinhole camera of the same rig is pruned at its own tighter level;
  //  - or its point is behind the camera;
  //  - or its depth exceeds max_depth_factor * the median depth of the rig
  //    observations, or is below that median / max_depth_factor (a point
  //    that collapsed onto a camera's centre: on EuRoC's map a refined
  //    point at 1e-7 of a map image's centre fitted its observations and
  //    gave that pose 1e26 of information, which left the uncertainty
  //    undetermined) (scene-scale relative: no map units are hard-coded).
  // The last two tests also run before the first solve, so that no residual
  // is ever evaluated behind a camera.
  double min_outlier_error_px = 2.0;
  double outlier_sigma_factor = 4.0;
  double max_depth_factor = 50.0;
  // Prune-and-resolve rounds after the first solve; stops early when a round
  // prunes nothing. 0: no pruning.
  int num_pruning_rounds = 2;
  // Solver threads (-1: all cores); the own solver's result does not depend
  // on them.
  int num_threads = -1;
  bool print_progress = false;  // per-iteration progress on stdout
  // The solver's backend (bundle_solver.h): the own one, or Ceres' to
  // compare with.
  BundleSolverBackend bundle_solver = BundleSolverBackend::kOwn;
  // The time model (see the top; both false: none, today's adjustment).
  bool estimate_time_offsets = false;  // delta_c, non-reference cameras
  bool estimate_line_delays = false;   // rho_c, every camera
  // Start values per dataset camera (empty: 0); the reference camera's
  // offset must be 0. Held at these when not estimated.
  std::vector<double> initial_time_offsets_s;
  std::vector<double> initial_line_delays_s;

  bool HasTimeModel() const {
    return estimate_time_offsets || estimate_line_delays;
  }
};

// One camera's capture timing from the adjustment's time model: offset
// delta_c (seconds, the reference camera 0) and line delay rho_c (seconds
// per row), whether each was estimated (else the value is the one held),
// and their 1-sigma uncertainties (AdjustRig leaves them 0; the capture-time
// model, capture_time_model.h, sets them from the calibration's uncertainty,
// NaN when it could not be computed).
struct CameraCaptureTime {
  bool time_offset_estimated = false;
  double time_offset_s = 0, time_offset_sigma_s = 0;
  bool line_delay_estimated = false;
  double line_delay_s = 0, line_delay_sigma_s = 0;
};

struct FinalBundleAdjustmentSummary {
  // RMS of the reprojection error over the observations of the first solve
  // at the initial estimate, and over the final inliers at the result.
  double initial_rms_px = 0, final_rms_px = 0;
  // Observations (2-vector residual blocks) in the last solve; observations
  // given as inliers and rejected (pruned, behind a camera, too far);
  // Levenberg-Marquardt iterations summed over all solves; wall time of
  // AdjustRig.
  int num_residuals = 0, num_outliers = 0, num_iterations = 0;
  double seconds = 0;
  // The map images' observations in the problem (of refined points): count
  // in the last solve, rejected, RMS at the initial estimate and the result.
  int num_map_residuals = 0, num_map_outliers = 0;
  double map_initial_rms_px = 0, map_final_rms_px = 0;
  std::string solver_report;  // BriefReport of the last solve
  // With a time model: per dataset camera (else empty).
  std::vector<CameraCaptureTime> capture_times;
};

// Minimizes the objective above over the correspondences with
// calibration->images[i].inlier_mask set, of the images whose frameset has a
// rig pose and whose camera is calibrated. Updates calibration->cameras,
// cam_from_rig, rig_from_world, images[i].inlier_mask / num_inliers / rms_px /
// used (images outside the adjustment get an all-zero mask and used = false)
// and, with refine_points, refined_points3D, and, with map images in the
// dataset, map_cameras, map_cam_from_world and map_observation_rejected. On
// bad input (a dataset that
// ValidateDataset rejects, inconsistent sizes, unknown camera model, no
// usable observation) or a solver failure it
// logs the reason, leaves `calibration` unchanged and returns false.
// `summary` may be null.
bool AdjustRig(const FinalBundleAdjustmentOptions& options,
               const RigDataset& dataset, RigCalibration* calibration,
               FinalBundleAdjustmentSummary* summary);

}  // namespace rig_calibrator
