#include "src/calibration/pipeline.h"

#include <colmap/util/timer.h>

#include <iostream>

#include "src/calibration/camera_model_stage.h"
#include "src/calibration/coverage_diagnosis.h"
#include "src/calibration/pipeline_stages.h"

namespace rig_calibrator {
namespace {

// Paper §3.2: every image localized on its own, with the pose model of the
// method.
void EstimateInitialPosesFor(const PipelineOptions& options,
                             CalibrationMethod method,
                             const RigDataset& dataset,
                             RigCalibration* calibration,
                             std::vector<colmap::Camera>* per_image_cameras,
                             PipelineReport* report) {
  StageTimer stage("Single-image localization", options.print_progress, report);
  InitialPoseOptions pose_options = options.initial_pose;
  pose_options.num_threads = options.num_threads;
  pose_options.seed = options.seed;
  pose_options.print_progress = options.print_progress;
  InitialPoseSummary summary;
  EstimateInitialPoses(pose_options, InitialPoseModelOf(method), dataset,
                       calibration, per_image_cameras, &summary);
  report->num_localized = summary.num_localized;
}

}  // namespace

// The method decides the stages; a 1dr rig with parallel principal axes
// falls back to rd_ra (see PipelineOptions).
bool CalibrateRig(const PipelineOptions& options, const RigDataset& dataset,
                  RigCalibration* calibration, PipelineReport* report) {
  colmap::Timer total_timer;
  total_timer.Start();
  *report = PipelineReport();
  report->requested_method = options.method;
  report->used_method = options.method;
  report->num_images = static_cast<int>(dataset.images.size());
  if (!ValidateDataset(dataset, &report->error)) return false;
  InitializeCalibration(dataset, calibration);

  CalibrationMethod method = options.method;
  std::vector<colmap::Camera> per_image_cameras;
  auto estimate_initial_poses = [&](CalibrationMethod for_method) {
    EstimateInitialPosesFor(options, for_method, dataset, calibration,
                            &per_image_cameras, report);
  };
  estimate_initial_poses(method);
  DiagnoseLocalization(dataset, *calibration, report);
  if (report->num_localized == 0) {
    report->error =
        "no image could be localized in the map: check that the rig images "
        "see the mapped scene and that their features match the map's";
    return false;
  }

  if (method == CalibrationMethod::kRadial1D) {
    std::string explanation;
    if (PrincipalAxesAreParallel(dataset, *calibration,
                                 options.parallel_axes_max_angle_deg,
                                 &explanation)) {
      if (!options.fallback_on_parallel_axes) {
        report->error = explanation +
                        " The 1D radial rig cannot be fixed from such a rig; "
                        "use --RigCalibrator.method rd_ra.";
        return false;
      }
      AddDiagnostic(report, Diagnostic::Level::kWarning,
                    "parallel_principal_axes",
                    explanation +
                        " The 1D radial rig cannot be fixed from such a rig "
                        "(paper, Limitations): falling back to rd_ra "
                        "(per-image pose and intrinsics, robust rig "
                        "initialization).");
      if (options.print_progress) {
        std::cout << "  parallel principal axes: falling back to rd_ra"
                  << std::endl;
      }
      method = CalibrationMethod::kRdRa;
      report->used_method = method;
      estimate_initial_poses(method);
    }
  }

  if (method == CalibrationMethod::kRadial1D) {
    if (!RunRadialStages(options, dataset, calibration, report)) return false;
  } else if (!RunFullPoseRigInitialization(options, method, dataset,
                                           per_image_cameras, calibration,
                                           report)) {
    return false;
  } else {
    ChooseCameraModelsFromPoses(options, dataset, calibration, report);
  }
  report->initial_cameras = calibration->cameras;
  report->initial_cam_from_rig = calibration->cam_from_rig;
  report->initial_camera_calibrated = calibration->camera_calibrated;
  if (!RunFinalBundleAdjustment(options, method, dataset, calibration,
                                report)) {
    return false;
  }
  // The capture-time model before the model choice: unmodelled offsets and
  // rolling shutters bend the residuals that the choice compares the
  // candidates on (on synthetic ring5 at 5 Hz with offsets it chose
  // SIMPLE_RADIAL_FISHEYE for a pinhole lens, docs/time_model.md). The
  // choice, the adjustment after a change and the validity check then take
  // each observation at its own instant.
  if (!RunCaptureTimeModel(options, method, dataset, calibration, report)) {
    return false;
  }
  if (ChooseCameraModelsOnAdjustedRig(options, method, dataset, calibration,
                                      report) &&
      !RunFinalBundleAdjustment(options, method, dataset, calibration, report,
                                "Final bundle adjustment, models changed")) {
    return false;
  }
  CheckCameraModels(options, dataset, *calibration, report);
  RunUncertaintyEstimation(options, method, dataset, *calibration, report);
  RunCaptureTiming(options, dataset, *calibration, report);
  SummarizeCalibration(dataset, *calibration, report);
  DiagnoseCoverage(dataset, *calibration, report);
  report->total_seconds = total_timer.ElapsedSeconds();
  return true;
}

}  // namespace rig_calibrator
