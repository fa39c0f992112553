// What `rig_calibrator [calibrate]` reports of a calibration: the summary
// written to calibration_summary.json and the result printed on the terminal.
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/io/calibration_summary.h"
#include "src/calibration/pipeline.h"

namespace rig_calibrator {

// SummarizeCalibration with the seed and the method, diagnostics and stage
// timings of the pipeline's report, compared with `known_rig` (if it has a
// reference camera).
CalibrationSummary MakeCalibrationSummary(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes,
    const PipelineReport& report, unsigned int seed,
    const KnownRigPrior& known_rig = KnownRigPrior());

// "== Result (method, seed, ...)", a line per camera (model, focal length,
// principal point, center in the rig, images used, RMS), the comparison with
// a known rig, then the diagnostics and the notes of the output writer.
void PrintResult(const RigDataset& dataset, const PipelineReport& report,
                 const CalibrationSummary& summary,
                 const std::vector<std::string>& notes);

// The diagnostics of a failed calibration, one per line, to stderr.
void PrintDiagnostics(const PipelineReport& report);

}  // namespace rig_calibrator
