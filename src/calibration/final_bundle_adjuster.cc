#include "src/calibration/final_bundle_adjuster.h"

#include <colmap/base/camera_models.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "src/calibration/map_anchoring.h"
#include "src/calibration/rig_adjustment.h"

namespace rig_calibrator {
namespace {

// The time model needs frameset times, two posed framesets for the rig's
// motion, and start values per camera (the reference camera's offset 0).
bool CheckTimeModelInput(const FinalBundleAdjustmentOptions& options,
                         const RigDataset& dataset,
                         const RigCalibration& calibration) {
  const char* const prefix = "Final bundle adjustment: the time model ";
  if (dataset.frameset_times_s.empty()) {
    LOG(ERROR) << prefix
               << "needs frameset times (RigDataset::frameset_times_s), "
                  "which this dataset does not have";
    return false;
  }
  if (std::count_if(calibration.rig_from_world.begin(),
                    calibration.rig_from_world.end(),
                    [](const auto& pose) { return pose.has_value(); }) < 2) {
    LOG(ERROR) << prefix << "needs at least two framesets with a rig pose";
    return false;
  }
  const size_t num_cameras = dataset.cameras.size();
  for (const std::vector<double>* values :
       {&options.initial_time_offsets_s, &options.initial_line_delays_s}) {
    if (!values->empty() &&
        (values->size() != num_cameras ||
         !std::all_of(values->begin(), values->end(),
                      [](double value) { return std::isfinite(value); }))) {
      LOG(ERROR) << prefix << "needs one finite start value per camera ("
                 << num_cameras << "), not " << values->size();
      return false;
    }
  }
  if (!options.initial_time_offsets_s.empty() &&
      options.initial_time_offsets_s[dataset.reference_camera] != 0) {
    LOG(ERROR) << prefix << "holds the reference camera's offset at 0; its "
                  "start value is "
               << options.initial_time_offsets_s[dataset.reference_camera];
    return false;
  }
  return true;
}

// Checks that the calibration matches the (valid) dataset and the options
// are usable, so that every index used later is valid.
bool CheckInput(const FinalBundleAdjustmentOptions& options,
                const RigDataset& dataset, const RigCalibration& calibration) {
  std::string error;
  if (!ValidateCalibration(dataset, calibration, &error)) {
    LOG(ERROR) << "Final bundle adjustment: " << error;
    return false;
  }
  if (!(options.loss_scale_px > 0) || options.max_num_iterations < 1 ||
      !(options.min_outlier_error_px > 0) ||
      !(options.outlier_sigma_factor > 0) || !(options.max_depth_factor > 1) ||
      options.num_pruning_rounds < 0) {
    LOG(ERROR) << "Final bundle adjustment: invalid options (loss scale, "
                  "iterations, outlier thresholds or pruning rounds)";
    return false;
  }
  if (options.refine_map &&
      (!options.refine_points || !options.use_map_observations ||
       dataset.map_images.empty())) {
    LOG(ERROR) << "Final bundle adjustment: refining the map needs the map "
                  "images and refine_points with use_map_observations";
    return false;
  }
  if (options.HasTimeModel() && !CheckTimeModelInput(options, dataset,
                                                      calibration)) {
    return false;
  }
  for (size_t camera = 0; camera < dataset.cameras.size(); ++camera) {
    const colmap::Camera& intrinsics = calibration.cameras[camera];
    if (calibration.camera_calibrated[camera] &&
        (!colmap::ExistsCameraModelWithId(intrinsics.ModelId()) ||
         !intrinsics.VerifyParams())) {
      LOG(ERROR) << "Final bundle adjustment: camera " << camera
                 << " has an unknown model or a wrong number of parameters";
      return false;
    }
  }
  return true;
}

// A solve whose only use is to tell the outliers from the inliers stops
// earlier: the residuals that decide the pruning (thresholds of 2 px or
// more) no longer move once the cost changes by 1e-3 per iteration, and the
// next solve starts from its result. Issue 14's scenario, 100 framesets x
// 10 cameras: the first solve takes 4 iterations instead of 11, all solves
// 13 instead of 15, with the same errors against the truth (0.018 / 0.019
// deg, 0.76 / 0.75 mm).
constexpr double kPruningFunctionTolerance = 1e-3;

// The first solve, then prune-and-resolve rounds until a round prunes
// nothing or num_pruning_rounds are done. A solve followed by a pruning
// round stops at kPruningFunctionTolerance; if that round prunes nothing,
// one more solve converges to kFinalBundleAdjustmentFunctionTolerance. Fills
// the counts of `result`.
bool SolveWithPruning(const FinalBundleAdjustmentOptions& options,
                      RigAdjustment* adjustment,
                      FinalBundleAdjustmentSummary* result) {
  BundleSolverSummary solver_summary;
  bool nothing_pruned = false;
  for (int round = 0;; ++round) {
    const bool last = round >= options.num_pruning_rounds;
    if (!adjustment->Solve(last || nothing_pruned
                               ? kFinalBundleAdjustmentFunctionTolerance
                               : kPruningFunctionTolerance,
                           &solver_summary)) {
      return false;
    }
    result->num_residuals = static_cast<int>(adjustment->NumObservations());
    result->num_map_residuals =
        static_cast<int>(adjustment->NumMapObservationsInProblem());
    result->num_iterations += solver_summary.num_successful_steps +
                              solver_summary.num_unsuccessful_steps;
    result->solver_report = solver_summary.BriefReport();
    if (last || nothing_pruned) {
      return true;
    }
    const size_t num_pruned =
        adjustment->RejectOutliers(/*prune_residuals=*/true);
    VLOG(1) << "Final bundle adjustment: pruned " << num_pruned
            << " outlier observations";
    // Nothing pruned: the next solve is the last, to full convergence.
    nothing_pruned = num_pruned == 0;
    if (adjustment->NumObservations() == 0) {
      LOG(ERROR) << "Final bundle adjustment: every observation was pruned";
      return false;
    }
  }
}

}  // namespace

bool AdjustRig(const FinalBundleAdjustmentOptions& options,
               const RigDataset& dataset, RigCalibration* calibration,
               FinalBundleAdjustmentSummary* summary) {
  const auto start_time = std::chrono::steady_clock::now();
  if (calibration == nullptr ||
      !CheckInput(options, dataset, *calibration)) {
    return false;
  }
  RigAdjustment adjustment(options, dataset, *calibration);
  adjustment.RejectOutliers(/*prune_residuals=*/false);
  if (adjustment.NumObservations() == 0) {
    LOG(ERROR) << "Final bundle adjustment: no inlier correspondence of a "
                  "calibrated camera in a frameset with a rig pose";
    return false;
  }
  FinalBundleAdjustmentSummary result;
  result.initial_rms_px = adjustment.RmsError();
  result.map_initial_rms_px = adjustment.MapRmsError();
  if (!SolveWithPruning(options, &adjustment, &result)) {
    return false;
  }
  if (options.HasTimeModel()) {
    // The last solve held the motion of the poses before it: solve once more
    // with the motion of its result (Solve recomputes it), so that the
    // result is consistent with its own motion model.
    BundleSolverSummary relinearized;
    if (!adjustment.Solve(kFinalBundleAdjustmentFunctionTolerance,
                          &relinearized)) {
      return false;
    }
    result.num_iterations += relinearized.num_successful_steps +
                             relinearized.num_unsuccessful_steps;
    result.solver_report = relinearized.BriefReport();
    result.capture_times = adjustment.CaptureTimes();
  }
  adjustment.RejectMapOutliers();
  result.final_rms_px = adjustment.RmsError();
  result.map_final_rms_px = adjustment.MapRmsError();
  result.num_outliers = static_cast<int>(adjustment.NumRejected());
  result.num_map_outliers = static_cast<int>(adjustment.NumMapRejected());
  adjustment.WriteTo(calibration);
  // The gauge (map_anchoring.h): fixed points or map poses anchor the world
  // frame; with none, the solution is moved back onto the map.
  if (options.refine_points && !adjustment.HasFixedPoints()) {
    if (options.refine_map) {
      AnchorMapImagesToMap(dataset, calibration);
    } else {
      AnchorRefinedPointsToMap(dataset, calibration);
    }
  }
  result.seconds = std::chrono::duration<double>(
                       std::chrono::steady_clock::now() - start_time)
                       .count();
  VLOG(1) << "Final bundle adjustment: RMS " << result.initial_rms_px << " -> "
          << result.final_rms_px << " px over " << result.num_residuals
          << " observations, " << result.num_outliers << " outliers; map RMS "
          << result.map_initial_rms_px << " -> " << result.map_final_rms_px
          << " px over " << result.num_map_residuals << " observations, "
          << result.num_map_outliers << " outliers, " << result.seconds << " s";
  if (summary != nullptr) {
    *summary = result;
  }
  return true;
}

}  // namespace rig_calibrator
