// The coverage and refinement part of `rig_calibrator [calibrate]`'s result:
// copied from the pipeline's report into the summary, and one terminal line
// per calibrated camera.
#pragma once

#include "colmap_ext/io/calibration_summary.h"
#include "src/calibration/pipeline_report.h"

namespace rig_calibrator {

// CameraSummary::coverage and refined from report.coverage and
// report.refined_intrinsics (left unset where the report has none).
void SetCoverageSummary(const PipelineReport& report,
                        CalibrationSummary* summary);

// "    coverage 87 % of 10x8 cells, radius 402.1 of 400.0 px (100 %); held:
// principal point" per camera with a coverage.
void PrintCoverage(const CalibrationSummary& summary);

}  // namespace rig_calibrator
