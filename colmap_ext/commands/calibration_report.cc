#include "colmap_ext/commands/calibration_report.h"

#include <iomanip>
#include <iostream>

namespace rig_calibrator {

CalibrationSummary MakeCalibrationSummary(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes,
    const PipelineReport& report, const unsigned int seed) {
  CalibrationSummary summary =
      SummarizeCalibration(dataset, calibration, image_prefixes);
  summary.method = CalibrationMethodName(report.used_method);
  summary.seed = seed;
  for (const Diagnostic& diagnostic : report.diagnostics) {
    summary.diagnostics.push_back(DiagnosticLevelName(diagnostic.level) + " " +
                                  diagnostic.code + ": " + diagnostic.message);
  }
  for (const StageTiming& timing : report.timings) {
    summary.timings_s.emplace_back(timing.stage, timing.seconds);
  }
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
              << camera.rms_px << " px\n";
  }
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
