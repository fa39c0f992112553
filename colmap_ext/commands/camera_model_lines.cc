#include "colmap_ext/commands/camera_model_lines.h"

#include <iomanip>
#include <iostream>

namespace rig_calibrator {

void PrintCameraModelLines(const CalibrationSummary& summary) {
  bool heading = false;
  for (const CameraSummary& camera : summary.cameras) {
    const CameraModelReport& report = camera.camera_model;
    if (!report.validity && !report.choice) continue;
    if (!heading) {
      std::cout << "  camera models:\n";
      heading = true;
    }
    std::cout << "    " << std::left << std::setw(8) << camera.name
              << std::right << " " << camera.camera.ModelName();
    if (report.validity) {
      std::cout << (report.validity->valid ? " valid" : " NOT valid")
                << (report.validity->fits_data
                        ? " over the whole image"
                        : " (does not follow the lens where there are data)");
      if (std::isfinite(report.validity->max_roundtrip_error_px)) {
        std::cout << " (round trip " << std::setprecision(2)
                  << report.validity->max_roundtrip_error_px << " px)";
      }
      if (!report.validity->suggested_model.empty()) {
        std::cout << ", suggested " << report.validity->suggested_model;
      }
    }
    if (report.choice) {
      std::cout << "; chosen automatically: " << report.choice->reason;
    }
    std::cout << std::defaultfloat << "\n";
  }
}

}  // namespace rig_calibrator
