// The calibration pipeline (paper §3) and the paper's baselines (§5.1) as
// methods of one entry point (calibration_method.h):
//
//   1dr           Inf+1DR+RA (default): 1D radial pose per image, robust radial
//                 rig initialization, radial BA with principal points, camera
//                 upgrade over all frames of each camera, final BA.
//   rd_ra         Inf+RD+RA: pose + intrinsics per image, robust rig
//                 initialization on full poses, final BA.
//   rd            Inf+RD: as rd_ra, but the rig is taken from the best complete
//                 frameset (Heng et al.'s initialization).
//   known         Inf+K: intrinsics given, full pose per image, the rig from
//                 the best complete frameset (Heng et al.), final BA of
//                 extrinsics and rig poses.
//   known_refine  Inf+K+RI: as known, intrinsics refined in the final BA.
//   known_ra      not in the paper: as known, with the robust rig
//                 initialization of rd_ra.
//
// Problems the pipeline can work around are reported as diagnostics instead
// of failures: e.g. a rig whose cameras all have parallel principal axes
// cannot be initialized from radial poses (paper, Limitations) and 1dr then
// falls back to rd_ra.
#pragma once

#include <string>
#include <vector>

#include "src/calibration/calibration_method.h"
#include "src/calibration/camera_upgrader.h"
#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/initial_pose_estimation.h"
#include "src/calibration/pipeline_report.h"
#include "src/calibration/principal_axes.h"
#include "src/calibration/radial_bundle_adjuster.h"
#include "src/calibration/rig_dataset.h"
#include "src/calibration/rig_initializer.h"

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
  FinalBundleAdjustmentOptions final_bundle_adjustment;

  // Correspondences within this radial error of the refined radial rig are
  // handed to the camera upgrade (pixels).
  double upgrade_radial_max_error_px = 8.0;

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
