// The coverage of every calibrated camera's image by its final inliers
// (src/calibration/image_coverage.h), in the pipeline's report, and a
// "poor_coverage" warning with the numbers for each camera it finds poor.
#pragma once

#include "src/calibration/pipeline_report.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

// Fills report->coverage (one entry per dataset camera, empty for a camera
// that was not calibrated) from the inliers of the used images, with
// calibration->cameras' principal points.
void DiagnoseCoverage(const RigDataset& dataset,
                      const RigCalibration& calibration,
                      PipelineReport* report);

}  // namespace rig_calibrator
