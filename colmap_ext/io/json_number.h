// A number of the JSON outputs (calibration_summary.json and its parts).
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>

namespace rig_calibrator {

// JSON has no NaN or infinity: a non-finite value (undetermined, not
// computed) becomes null.
inline nlohmann::ordered_json JsonNumber(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value)
                              : nlohmann::ordered_json(nullptr);
}

}  // namespace rig_calibrator
