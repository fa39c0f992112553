// The methods of the paper's experiment tables (paper §5.1): Table 1
// (accuracy) compares Inf+K, Inf+K+RI, Inf+RD, Inf+RD+RA and Inf+1DR+RA
// (known, known_refine, rd, rd_ra, 1dr); Table 3 (robustness) Inf+RD,
// Inf+RD+RA and Inf+1DR+RA (rd, rd_ra, 1dr).
#pragma once

#include <vector>

#include "src/calibration/calibration_method.h"

namespace rig_calibrator {

std::vector<CalibrationMethod> AccuracyTableMethods();
std::vector<CalibrationMethod> RobustnessTableMethods();

}  // namespace rig_calibrator
