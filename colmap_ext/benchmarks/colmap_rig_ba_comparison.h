// Side by side with COLMAP 3.8's `rig_bundle_adjuster` (issue 14): the same
// rig bundle adjustment problem solved by COLMAP's command (a child process
// of the extended colmap executable) and by this project's final bundle
// adjustment (AdjustRig, in process), from the same start, to the same
// convergence criterion, in one run
// (`rig_calibrator_lab benchmark_colmap_rig_ba`).
//
// The start: a synthetic ring rig (runtime benchmark's data) calibrated by
// the 1dr pipeline up to the input of its final bundle adjustment (single-
// image localization, radial stages, full inliers). The compared problem:
//   min sum_{i,p} |pi_theta_c(i)(P_c(i) Q_f(i) X_p) - x_ip|^2
// over every intrinsic parameter theta_c, every non-reference cam_from_rig
// P_c, every rig_from_world Q_f and every point X_p, over the start's inlier
// observations of points seen at least twice, of framesets that have an
// image of the reference camera (COLMAP adjusts the others' images as free
// images, not as rig snapshots). COLMAP's command has no robust loss option
// and no pruning; AdjustRig gets no pruning round and a Cauchy scale far above
// every compared residual (weights within a percent of 1).
#pragma once

#include <colmap/base/camera.h>

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "src/calibration/final_bundle_adjuster.h"
#include "src/geometry/rigid3d.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

struct ColmapRigBaComparisonOptions {
  std::string output_path;  // gets colmap_rig_ba.md and colmap_rig_ba.csv
  // Comma-separated: one comparison per frameset count x camera count.
  std::string framesets = "100,500";
  std::string cameras = "10";
  // The extended colmap executable (empty: `colmap` beside this executable).
  std::string colmap_executable;
  // Both stop when an iteration lowers the cost by less than this share of
  // it: AdjustRig's own, not an option of it; given to COLMAP as
  // --BundleAdjustment.function_tolerance.
  double function_tolerance = kFinalBundleAdjustmentFunctionTolerance;
  int max_num_iterations = 100;
  // AdjustRig's Cauchy scale: rho(s) = b^2 log(1 + s / b^2) weighs a residual
  // r by 1 / (1 + r^2 / b^2), so with b = 100 px and the inliers within the
  // pipeline's 10 px (CameraUpgradeOptions::max_error_px), every weight is
  // above 0.99: the trivial loss of COLMAP up to that. (A far larger b loses
  // the cost's digits: Ceres evaluates log(1 + x), not log1p.)
  double loss_scale_px = 100.0;
  SyntheticRigOptions data = [] {
    SyntheticRigOptions data;
    data.map_point_noise = 0.005;
    return data;
  }();
  int seed = 0;
  bool keep_work_folder = false;  // keep the COLMAP models (logged path)
};

// COLMAP's PrintSolverSummary (src/optim/bundle_adjustment.cc), as printed
// by rig_bundle_adjuster after its "Rig Bundle adjustment report" heading.
struct ColmapSolverSummary {
  int64_t num_residuals = 0;  // scalar residuals (2 per observation)
  int num_iterations = 0;     // successful + unsuccessful steps
  double seconds = 0;         // Ceres' total_time_in_seconds
  // sqrt(cost / num_residuals) with cost = 0.5 sum |e|^2: half the RMS of
  // the reprojection error per observation.
  double initial_cost_px = 0, final_cost_px = 0;
  std::string termination;  // "Convergence", "No convergence", ...
  int num_snapshots = 0;    // "Snapshots: N" of the rig configuration
};

// Parses the last summary in COLMAP's standard output; false with *error
// naming the missing field.
bool ParseColmapSolverSummary(const std::string& text,
                              ColmapSolverSummary* summary, std::string* error);

// One 2D observation of a 3D point by an image (indices into a ModelView).
struct ObservedPoint {
  int image = -1;
  int64_t point3D_id = -1;
  Eigen::Vector2d point2D = Eigen::Vector2d::Zero();
};

// What the reprojection error needs of a solution: per image its camera and
// cam_from_world, and the points by id.
struct ModelView {
  std::vector<colmap::Camera> image_cameras;
  std::vector<Rigid3d> image_cam_from_world;
  std::unordered_map<int64_t, Eigen::Vector3d> points3D;
};

struct ReprojectionRms {
  // sqrt(sum |pi(R X + t) - x|^2 / N) over the N usable observations (0 for
  // none).
  double rms_px = 0;
  int64_t num_used = 0;
  // Behind their camera, or of an unknown image or point: not in the RMS.
  int64_t num_unusable = 0;
};
ReprojectionRms RmsReprojectionError(
    const std::vector<ObservedPoint>& observations, const ModelView& view);

// Runs every comparison and writes the table and the CSV; false with *error
// on bad options or a failed run.
bool RunColmapRigBaComparison(const ColmapRigBaComparisonOptions& options,
                              std::string* error);

}  // namespace rig_calibrator
