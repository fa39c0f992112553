// The calibration pipeline (paper §3) and the paper's baselines (§5.1) as
// methods of one entry point:
//
//   1dr           Inf+1DR+RA (default): 1D radial pose per image, robust radial
//                 rig initialization, radial BA with principal points, camera
//                 upgrade over all frames of each camera, final BA.
//   rd_ra         Inf+RD+RA: pose + intrinsics per image, robust rig
//                 initialization on full poses, final BA.
//   rd            Inf+RD: as rd_ra, but the rig is taken from the best complete
//                 frameset (Heng et al.'s initialization).
//   known         Inf+K: intrinsics given, full pose per image, robust rig
//                 initialization, final BA of extrinsics and rig poses.
//   known_refine  Inf+K+RI: as known, intrinsics refined in the final BA.
//
// Problems the pipeline can work around are reported as diagnostics instead
// of failures: e.g. a rig whose cameras all have parallel principal axes
// cannot be initialized from radial poses (paper, Limitations) and 1dr then
// falls back to rd_ra.
#pragma once

#include <string>
#include <vector>

#include "src/calibration/camera_upgrader.h"
#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/initial_pose_estimation.h"
#include "src/calibration/principal_axes.h"
#include "src/calibration/radial_bundle_adjuster.h"
#include "src/calibration/rig_dataset.h"
#include "src/calibration/rig_initializer.h"

namespace rig_calibrator {

enum class CalibrationMethod { kKnown, kKnownRefine, kRd, kRdRa, kRadial1D };

// "known", "known_refine", "rd", "rd_ra", "1dr".
bool CalibrationMethodFromName(const std::string& name,
                               CalibrationMethod* method);
std::string CalibrationMethodName(CalibrationMethod method);

struct Diagnostic {
  enum class Level { kInfo, kWarning, kError };
  Level level = Level::kInfo;
  std::string code;  // stable identifier, e.g. "parallel_principal_axes"
  std::string message;
  std::vector<int> cameras;    // camera indices concerned
  std::vector<int> framesets;  // frameset indices concerned
};
std::string DiagnosticLevelName(Diagnostic::Level level);

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

struct StageTiming {
  std::string stage;
  double seconds = 0;  // wall time
  // CPU time of the whole process (all threads, user + system) during the
  // stage: unlike wall time, hardly affected by other work on the machine.
  double cpu_seconds = 0;
};

struct PipelineReport {
  CalibrationMethod requested_method = CalibrationMethod::kRadial1D;
  CalibrationMethod used_method = CalibrationMethod::kRadial1D;
  std::vector<Diagnostic> diagnostics;
  std::vector<StageTiming> timings;
  int num_images = 0;
  int num_localized = 0;  // on their own, in the first stage
  int num_used = 0;       // in the final calibration
  int num_framesets_posed = 0;
  double final_rms_px = 0;
  double total_seconds = 0;
  // The rig as it entered the final bundle adjustment (paper Fig. 6, the
  // "initial estimates"): from the rig initialization (rd, rd_ra, known*) or
  // the camera upgrade (1dr). Empty when the pipeline stopped before.
  std::vector<colmap::Camera> initial_cameras;
  std::vector<Rigid3d> initial_cam_from_rig;
  std::vector<bool> initial_camera_calibrated;
  // Why the pipeline stopped, when CalibrateRig returns false.
  std::string error;

  bool HasErrors() const;
};

// Calibrates every camera of `dataset` (intrinsics and cam_from_rig) and the
// rig pose of every frameset. Returns false with report->error set when no
// calibration could be made; cameras that could not be calibrated while
// others were are reported in report->diagnostics and have
// calibration->camera_calibrated false.
bool CalibrateRig(const PipelineOptions& options, const RigDataset& dataset,
                  RigCalibration* calibration, PipelineReport* report);

}  // namespace rig_calibrator
