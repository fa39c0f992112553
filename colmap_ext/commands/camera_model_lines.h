// The terminal lines of the result about camera models: per camera whether
// its model is valid over the whole image and, where it was chosen
// automatically, which model and why (the candidates' table is printed
// during the camera upgrade).
#pragma once

#include "colmap_ext/io/calibration_summary.h"

namespace rig_calibrator {

void PrintCameraModelLines(const CalibrationSummary& summary);

}  // namespace rig_calibrator
