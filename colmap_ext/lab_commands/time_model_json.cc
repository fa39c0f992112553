#include "colmap_ext/lab_commands/time_model_json.h"

#include <nlohmann/json.hpp>

#include "colmap_ext/io/atomic_output.h"

namespace rig_calibrator {

bool WriteTimeModelJson(const std::string& path,
                        const SyntheticRigOptions& options,
                        const std::vector<std::string>& frameset_names,
                        const RigGroundTruth& truth, std::string* error) {
  nlohmann::ordered_json json;
  json["capture_time"] =
      "camera c captures the row through pixel y (COLMAP pixels, the top "
      "row's centre at y = 0.5) of frameset f at frameset_times_s[f] + "
      "time_offset_s + line_delay_s * (y - 0.5) seconds";
  json["frameset_rate_hz"] = options.frameset_rate_hz;
  json["speed_m_s"] = options.speed_m_s;
  json["max_turn_rate_deg_s"] = options.max_turn_rate_deg_s;
  json["reference_camera"] = truth.camera_names[0];
  nlohmann::ordered_json cameras = nlohmann::ordered_json::array();
  for (size_t c = 0; c < truth.cameras.size(); ++c) {
    cameras.push_back({{"name", truth.camera_names[c]},
                       {"time_offset_s", truth.time_offsets_s[c]},
                       {"line_delay_s", truth.line_delays_s[c]},
                       {"rows", truth.cameras[c].Height()}});
  }
  json["cameras"] = cameras;
  nlohmann::ordered_json framesets = nlohmann::ordered_json::array();
  for (size_t f = 0; f < truth.frameset_times_s.size(); ++f) {
    framesets.push_back({{"name", frameset_names[f]},
                         {"time_s", truth.frameset_times_s[f]}});
  }
  json["framesets"] = framesets;
  return WriteFileAtomically(path, json.dump(2) + "\n", error);
}

}  // namespace rig_calibrator
