// The stages of CalibrateRig (pipeline.h) after the single-image
// localization, each timed and reported: the radial stages of 1dr (paper
// §3.3-3.5), the rig initialization of the full-pose methods, and the final
// bundle adjustment (§3.6). Each returns false with report->error set when
// the calibration cannot go on.
#pragma once

#include <vector>

#include "src/calibration/pipeline.h"

namespace rig_calibrator {

// The calibration before any stage: the dataset's cameras, nothing posed.
void InitializeCalibration(const RigDataset& dataset,
                           RigCalibration* calibration);

// 1dr: robust radial rig initialization, radial bundle adjustment, camera
// upgrade of every camera; the rig is then anchored at the reference camera.
bool RunRadialStages(const PipelineOptions& options, const RigDataset& dataset,
                     RigCalibration* calibration, PipelineReport* report);

// The full-pose methods: per-camera intrinsics (the median over the images,
// rd and rd_ra; given, known*) and the rig, from the best complete frameset
// (known, known_refine, rd) or robustly (rd_ra, known_ra).
bool RunFullPoseRigInitialization(
    const PipelineOptions& options, CalibrationMethod method,
    const RigDataset& dataset,
    const std::vector<colmap::Camera>& per_image_cameras,
    RigCalibration* calibration, PipelineReport* report);

// The final bundle adjustment's options for `method` (refinement switches,
// threads, map adjustment only with map images).
FinalBundleAdjustmentOptions FinalBundleAdjustmentOptionsFor(
    const PipelineOptions& options, CalibrationMethod method,
    const RigDataset& dataset);

// The final bundle adjustment over the full inliers of the current rig;
// the intrinsics are held for known and known_ra.
// `stage_name` names it in the report (it runs twice when the model choice
// on the adjusted rig changed a model).
bool RunFinalBundleAdjustment(const PipelineOptions& options,
                              CalibrationMethod method,
                              const RigDataset& dataset,
                              RigCalibration* calibration,
                              PipelineReport* report,
                              const std::string& stage_name =
                                  "Final bundle adjustment");

// With frameset times and a capture-time mode not off: the final bundle
// adjustment with the time model (capture_time_model.h) into
// report->capture_time_model, replacing the calibration when a kind is
// kept. Fails only when a mode is on and the model cannot run.
bool RunCaptureTimeModel(const PipelineOptions& options,
                         CalibrationMethod method, const RigDataset& dataset,
                         RigCalibration* calibration, PipelineReport* report);

// The uncertainty of the final bundle adjustment's result
// (src/calibration/calibration_uncertainty.h) into report->uncertainty, and
// its diagnostics. Never fails the calibration.
void RunUncertaintyEstimation(const PipelineOptions& options,
                              CalibrationMethod method,
                              const RigDataset& dataset,
                              const RigCalibration& calibration,
                              PipelineReport* report);

// With frameset times and at least two calibrated cameras: the capture-time
// offsets of the cameras (capture_timing.h) into report->capture_timing, and
// the warning unsynchronized_cameras naming those whose offset is
// significant. Otherwise nothing (no stage, no output). Never fails the
// calibration.
void RunCaptureTiming(const PipelineOptions& options, const RigDataset& dataset,
                      const RigCalibration& calibration,
                      PipelineReport* report);

}  // namespace rig_calibrator
