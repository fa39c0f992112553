#include "src/calibration/coverage_diagnosis.h"

#include <vector>

namespace rig_calibrator {

void DiagnoseCoverage(const RigDataset& dataset,
                      const RigCalibration& calibration,
                      PipelineReport* report) {
  const size_t num_cameras = dataset.cameras.size();
  std::vector<std::vector<Eigen::Vector2d>> points(num_cameras);
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    const ImageResult& result = calibration.images[i];
    if (!result.used) continue;
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      if (k < result.inlier_mask.size() && result.inlier_mask[k]) {
        points[image.camera_index].push_back(image.correspondences[k].point2D);
      }
    }
  }
  report->coverage.assign(num_cameras, std::nullopt);
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!calibration.camera_calibrated[c]) continue;
    report->coverage[c] =
        ComputeImageCoverage(calibration.cameras[c], points[c]);
    std::string why;
    if (IsPoorCoverage(*report->coverage[c], &why)) {
      AddDiagnostic(report, Diagnostic::Level::kWarning, "poor_coverage",
                    "camera " + dataset.cameras[c].name +
                        ": poor coverage of the image by its " +
                        std::to_string(report->coverage[c]->num_points) +
                        " inliers: " + why +
                        ". Record images with the scene's structure in every "
                        "part of this camera's view, out to its corners.",
                    {static_cast<int>(c)});
    }
  }
}

}  // namespace rig_calibrator
