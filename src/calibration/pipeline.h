// The calibration pipeline (paper §3): one entry point for the paper's method
// and its baselines (§5.1), which differ per stage as calibration_method.h
// lists. The stages, in order (pipeline_stages.h): single-image localization
// (initial_pose_estimation.h), rig initialization (rig_initializer.h or
// complete_frameset_initialization.h), for 1dr the radial bundle adjustment
// and the camera upgrade (radial_bundle_adjuster.h, camera_upgrader.h), and
// the final bundle adjustment (final_bundle_adjuster.h), the model choice
// on the adjusted rig for cameras whose model is "auto"
// (model_choice_after_adjustment.h; the final adjustment runs again when a
// model changed), the model checks and the uncertainty.
//
// Problems the pipeline can work around are reported as diagnostics instead
// of failures (pipeline_report.h): e.g. a rig whose cameras all have parallel
// or anti-parallel principal axes cannot be initialized from radial poses
// (paper, Limitations; principal_axes.h) and 1dr then falls back to rd_ra.
#pragma once

#include <string>
#include <vector>

#include "src/calibration/calibration_method.h"
#include "src/calibration/camera_upgrader.h"
#include "src/calibration/capture_time_model.h"
#include "src/calibration/capture_timing.h"
#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/initial_pose_estimation.h"
#include "src/calibration/model_choice_after_adjustment.h"
#include "src/calibration/model_selection.h"
#include "src/calibration/pipeline_report.h"
#include "src/calibration/principal_axes.h"
#include "src/calibration/radial_bundle_adjuster.h"
#include "src/calibration/rig_initializer.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

struct PipelineOptions {
  CalibrationMethod method = CalibrationMethod::kRadial1D;
  // 1dr on a rig with parallel principal axes: fall back to rd_ra (else fail).
  bool fallback_on_parallel_axes = true;
  // Rigs on which every pair of cameras is within this angle of parallel or
  // anti-parallel (e.g. a stereo pair, a front/back pair) count as parallel
  // (PrincipalAxesAreParallel; why 10 degrees: principal_axes.h).
  double parallel_axes_max_angle_deg = kParallelAxesMaxAngleDeg;

  InitialPoseOptions initial_pose;
  RigInitializerOptions rig_initializer;
  RadialBundleAdjustmentOptions radial_bundle_adjustment;
  CameraUpgradeOptions upgrade;
  ModelSelectionOptions model_selection;  // cameras with choose_model
  // The choice made again after the final adjustment (its loss scale,
  // inlier threshold, principal point switch and validity options are the
  // pipeline's: set when it runs).
  ModelChoiceAfterAdjustmentOptions model_choice_after_adjustment;
  FinalBundleAdjustmentOptions final_bundle_adjustment;
  // The capture-time offsets after the final adjustment, when the dataset
  // has frameset times (capture_timing.h).
  CaptureTimingOptions capture_timing;
  // The final adjustment with capture-time offsets and line delays, when
  // the dataset has frameset times (capture_time_model.h); its start
  // estimate and inlier threshold are set from the options above.
  CaptureTimeModelOptions capture_time_model;

  // Correspondences within this radial error of the refined radial rig are
  // handed to the camera upgrade (pixels).
  double upgrade_radial_max_error_px = 8.0;

  // Threads of every stage. The results do not depend on the count: the
  // stages split their work by image or camera, and the bundle adjustments'
  // own solver (bundle_levenberg_marquardt.h; not the ceres backend) adds its
  // parts in a fixed order, so the calibration is bit-identical for a seed,
  // whatever num_threads.
  int num_threads = -1;
  unsigned int seed = 0;
  bool print_progress = true;
};

// Calibrates every camera of `dataset` (intrinsics and cam_from_rig) and the
// rig pose of every frameset. Returns false with report->error set when no
// calibration could be made; cameras that could not be calibrated while
// others were are reported in report->diagnostics and have
// calibration->camera_calibrated false.
bool CalibrateRig(const PipelineOptions& options, const RigDataset& dataset,
                  RigCalibration* calibration, PipelineReport* report);

}  // namespace rig_calibrator
