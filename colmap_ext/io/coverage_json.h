// The "coverage" and "refined" keys of a camera in calibration_summary.json
// (the contract of issue 12):
//   "coverage": {"grid": {"cols": C, "rows": R, "counts": [R*C row-major]},
//                "fraction_cells": f, "max_observed_radius_px": r,
//                "corner_radius_px": rc, "radius_ratio": r / rc}
//   "refined": {"focal_length": b, "principal_point": b, "extra_params": b}
// Each is absent when not computed (a camera that was not calibrated).
#pragma once

#include <nlohmann/json.hpp>

#include "colmap_ext/io/calibration_summary.h"

namespace rig_calibrator {

void AddCoverageJson(const CameraSummary& camera, nlohmann::ordered_json* node);

}  // namespace rig_calibrator
