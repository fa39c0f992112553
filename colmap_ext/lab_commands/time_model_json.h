// ground_truth/time_model.json, the true time model of a lab dataset
// (`rig_calibrator_lab synthetic` and `render` with --frameset_rate_hz > 0).
#pragma once

#include <string>
#include <vector>

#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// Writes the frameset rate, the rig's speed and turn rate (from `options`),
// per camera of `truth` its capture-time offset, line delay and rows, and per
// frameset its name and time (seconds); camera c captures the row through
// pixel y of frameset f at frameset_times_s[f] + time_offset_s +
// line_delay_s (y - 0.5).
bool WriteTimeModelJson(const std::string& path,
                        const SyntheticRigOptions& options,
                        const std::vector<std::string>& frameset_names,
                        const RigGroundTruth& truth, std::string* error);

}  // namespace rig_calibrator
