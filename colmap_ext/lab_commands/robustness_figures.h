// The figures of the robustness experiment (src/experiments/
// robustness_experiment.h) in `rig_calibrator_lab benchmark`'s results,
// drawn with the report's charts (colmap_ext/report/svg_plot.h).
#pragma once

#include <string>
#include <vector>

#include "src/experiments/robustness_experiment.h"

namespace rig_calibrator {

// Paper Fig. 6: cumulative distributions, over every camera of every
// sequence of the cell, of the rotation (`rotation` true, degrees) or center
// (cm) error of the rig before the final bundle adjustment, one curve per
// method; with `final_errors` the errors after it instead.
std::string ErrorDistributionSvg(const RobustnessCell& cell, bool rotation,
                                 bool final_errors);

// Grouped bars of the share of good calibrations: one group per cell, one
// bar per method.
std::string GoodCalibrationsSvg(const std::vector<RobustnessCell>& cells);

}  // namespace rig_calibrator
