#include "colmap_ext/commands/coverage_report.h"

#include <iomanip>
#include <iostream>
#include <string>

namespace rig_calibrator {

void SetCoverageSummary(const PipelineReport& report,
                        CalibrationSummary* summary) {
  for (size_t c = 0; c < summary->cameras.size(); ++c) {
    if (c < report.coverage.size()) {
      summary->cameras[c].coverage = report.coverage[c];
    }
    if (c < report.refined_intrinsics.size()) {
      summary->cameras[c].refined = report.refined_intrinsics[c];
    }
  }
}

void PrintCoverage(const CalibrationSummary& summary) {
  for (const CameraSummary& camera : summary.cameras) {
    if (!camera.coverage) continue;
    const ImageCoverage& coverage = *camera.coverage;
    std::string held;
    if (camera.refined) {
      const auto add = [&held](bool refined, const std::string& name) {
        if (!refined) held += (held.empty() ? "" : ", ") + name;
      };
      add(camera.refined->focal_length, "focal length");
      add(camera.refined->principal_point, "principal point");
      add(camera.refined->extra_params, "distortion");
    }
    std::cout << "    " << std::left << std::setw(8) << camera.name
              << std::right << " coverage " << std::fixed
              << std::setprecision(0) << 100 * coverage.fraction_cells
              << " % of " << coverage.grid_cols << "x" << coverage.grid_rows
              << " cells, radius " << std::setprecision(1)
              << coverage.max_observed_radius_px << " of "
              << coverage.corner_radius_px << " px (" << std::setprecision(0)
              << 100 * coverage.radius_ratio << " %)"
              << (held.empty() ? "" : "; held at the given values: " + held)
              << "\n"
              << std::defaultfloat;
  }
}

}  // namespace rig_calibrator
