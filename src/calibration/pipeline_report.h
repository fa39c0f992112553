// What CalibrateRig (pipeline.h) reports besides the calibration: the
// diagnostics of problems it worked around, the stage timings, counts and the
// rig as it entered the final bundle adjustment; and the helpers the pipeline
// stages use to fill it.
#pragma once

#include <colmap/util/timer.h>

#include <optional>
#include <string>
#include <vector>

#include "src/calibration/calibration_method.h"
#include "src/calibration/calibration_uncertainty.h"
#include "src/calibration/camera_model_report.h"
#include "src/calibration/capture_time_model.h"
#include "src/calibration/capture_timing.h"
#include "src/calibration/image_coverage.h"
#include "src/calibration/stage_timing.h"
#include "src/rig/intrinsics_refinement.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

struct Diagnostic {
  enum class Level { kInfo, kWarning, kError };
  Level level = Level::kInfo;
  std::string code;  // stable identifier, e.g. "parallel_principal_axes"
  std::string message;
  std::vector<int> cameras;    // camera indices concerned
  std::vector<int> framesets;  // frameset indices concerned
};
std::string DiagnosticLevelName(Diagnostic::Level level);


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
  // The uncertainty of the final calibration (computed after the final
  // bundle adjustment).
  CalibrationUncertainty uncertainty;
  // Per dataset camera: its model's validity and automatic choice (empty
  // when the pipeline stopped before the final bundle adjustment).
  std::vector<CameraModelReport> camera_models;
  // Per camera, the intrinsics the pipeline estimated (the others held at
  // their given values); empty when it stopped before the final adjustment.
  std::vector<IntrinsicsRefinement> refined_intrinsics;
  // Per camera, the coverage of its image by the final inliers (none for a
  // camera that was not calibrated; coverage_diagnosis.h).
  std::vector<std::optional<ImageCoverage>> coverage;
  // The capture-time offsets measured after the final adjustment
  // (capture_timing.h); `computed` false when the dataset has no frameset
  // times.
  CaptureTiming capture_timing;
  // The time model of the final adjustment (capture_time_model.h);
  // `computed` false when it did not run.
  CaptureTimeModel capture_time_model;
  // Why the pipeline stopped, when CalibrateRig returns false.
  std::string error;

  bool HasErrors() const;
};

void AddDiagnostic(PipelineReport* report, Diagnostic::Level level,
                   const std::string& code, const std::string& message,
                   std::vector<int> cameras = {},
                   std::vector<int> framesets = {});

// "cam0, cam2": the names of the dataset cameras.
std::string CameraList(const RigDataset& dataset,
                       const std::vector<int>& cameras);

// Reports cameras with no localized image, and cameras that were localized
// but never in a frameset together with another localized camera (nothing
// ties them to the rig).
void DiagnoseLocalization(const RigDataset& dataset,
                          const RigCalibration& calibration,
                          PipelineReport* report);

// Reports the cameras that ended uncalibrated (an error) and counts the used
// images and posed framesets.
void SummarizeCalibration(const RigDataset& dataset,
                          const RigCalibration& calibration,
                          PipelineReport* report);

// Times a stage and prints its heading; the destructor records the wall and
// CPU times in the report.
class StageTimer {
 public:
  StageTimer(const std::string& name, bool print, PipelineReport* report);
  ~StageTimer();

  void SetNumIterations(int num_iterations) {
    num_iterations_ = num_iterations;
  }

 private:
  std::string name_;
  int num_iterations_ = 0;
  PipelineReport* report_;
  colmap::Timer timer_;
  double cpu_start_;
};

}  // namespace rig_calibrator
