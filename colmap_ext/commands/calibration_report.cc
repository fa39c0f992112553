#include "colmap_ext/commands/calibration_report.h"

#include <iomanip>
#include <iostream>

#include "colmap_ext/commands/camera_model_lines.h"
#include "colmap_ext/commands/coverage_report.h"
#include "colmap_ext/io/model_validity_json.h"
#include "colmap_ext/io/uncertainty_json.h"

namespace rig_calibrator {
namespace {

std::vector<std::string> CameraNames(const CalibrationSummary& summary) {
  std::vector<std::string> names;
  for (const CameraSummary& camera : summary.cameras)
    names.push_back(camera.name);
  return names;
}

std::vector<colmap::Camera> CameraModels(const CalibrationSummary& summary) {
  std::vector<colmap::Camera> cameras;
  for (const CameraSummary& camera : summary.cameras) {
    cameras.push_back(camera.camera);
  }
  return cameras;
}

}  // namespace

CalibrationSummary MakeCalibrationSummary(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes,
    const PipelineReport& report, const unsigned int seed,
    const KnownRigPrior& known_rig) {
  CalibrationSummary summary =
      SummarizeCalibration(dataset, calibration, image_prefixes);
  CompareWithKnownRig(known_rig, &summary);
  AttachCameraModelReports(report, &summary);
  summary.method = CalibrationMethodName(report.used_method);
  summary.seed = seed;
  summary.uncertainty = report.uncertainty;
  summary.capture_timing = report.capture_timing;
  summary.capture_time_model = report.capture_time_model;
  // The adjustment's timing when it modelled time, else the measurement
  // after the calibration (camera_timing.h).
  std::vector<std::optional<CameraTiming>> timings =
      AdjustedCameraTimings(report.capture_time_model);
  if (timings.empty()) {
    timings =
        MeasuredCameraTimings(report.capture_timing, dataset.reference_camera);
  }
  for (size_t c = 0; c < timings.size() && c < summary.cameras.size(); ++c) {
    summary.cameras[c].timing = timings[c];
  }
  for (const Diagnostic& diagnostic : report.diagnostics) {
    summary.diagnostics.push_back(DiagnosticLevelName(diagnostic.level) + " " +
                                  diagnostic.code + ": " + diagnostic.message);
  }
  summary.timings = report.timings;
  SetCoverageSummary(report, &summary);
  return summary;
}

void PrintResult(const RigDataset& dataset, const PipelineReport& report,
                 const CalibrationSummary& summary,
                 const std::vector<std::string>& notes) {
  std::cout << "\n== Result (" << CalibrationMethodName(report.used_method)
            << ", seed " << summary.seed << ", " << report.num_used << " of "
            << report.num_images << " images used, "
            << report.num_framesets_posed << " of "
            << dataset.frameset_names.size() << " framesets, RMS "
            << std::setprecision(3) << report.final_rms_px << " px, "
            << std::fixed << std::setprecision(1) << report.total_seconds
            << " s)\n"
            << std::defaultfloat;
  for (const CameraSummary& camera : summary.cameras) {
    std::cout << "  " << std::left << std::setw(8) << camera.name << std::right;
    if (!camera.calibrated) {
      std::cout << " not calibrated\n";
      continue;
    }
    const Eigen::Vector3d center = camera.cam_from_rig->Center();
    std::cout << " " << camera.camera.ModelName() << " f "
              << std::setprecision(2) << std::fixed
              << camera.camera.MeanFocalLength() << " pp ("
              << camera.camera.PrincipalPointX() << ", "
              << camera.camera.PrincipalPointY() << ") center in rig ("
              << std::setprecision(4) << center.x() << ", " << center.y()
              << ", " << center.z() << ") images " << camera.num_used << "/"
              << camera.num_images << " RMS " << std::setprecision(3)
              << camera.rms_px << " px"
              << (camera.timing ? " " + CameraTimingText(*camera.timing) : "")
              << "\n";
  }
  for (const std::string& line : UncertaintyLines(
           CameraNames(summary), CameraModels(summary), summary.uncertainty)) {
    std::cout << "  " << line << "\n";
  }
  PrintCoverage(summary);
  if (report.capture_timing.computed) {
    std::cout << "  "
              << CaptureTimingLine(CameraNames(summary),
                                   dataset.reference_camera,
                                   report.capture_timing)
              << "\n";
  }
  if (!summary.known_rig_source.empty()) {
    std::cout << "  against the known rig of " << summary.known_rig_source
              << " (cam_from_" << summary.known_rig_reference_camera << "):\n";
    for (const KnownPoseComparison& comparison : summary.known_rig_comparison) {
      std::cout << "    " << std::left << std::setw(8) << comparison.camera
                << std::right << " rotation " << std::setprecision(3)
                << comparison.rotation_error_deg << " deg, translation "
                << std::setprecision(4) << comparison.translation_error
                << " map units (known " << comparison.known_translation_norm
                << ")\n";
    }
  }
  PrintCameraModelLines(summary);
  for (const Diagnostic& diagnostic : report.diagnostics) {
    std::cout << "  " << DiagnosticLevelName(diagnostic.level) << ": "
              << diagnostic.message << "\n";
  }
  std::cout << std::flush;
  for (const std::string& note : notes) std::cout << "  note: " << note << "\n";
}

void PrintDiagnostics(const PipelineReport& report) {
  for (const Diagnostic& diagnostic : report.diagnostics) {
    std::cerr << DiagnosticLevelName(diagnostic.level) << ": "
              << diagnostic.message << std::endl;
  }
}

}  // namespace rig_calibrator
