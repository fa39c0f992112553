// Reads a rig calibration from any of the formats rig_calibrator writes or
// that other tools give: an output folder of rig_calibrator, a
// rig_config.json (COLMAP >= 3.12) or a camchain.yaml (Kalibr).
#pragma once

#include <string>

#include "colmap_ext/io/rig_description.h"

namespace rig_calibrator {

// `path` is a folder (its rig_config.json is read, with image sizes from its
// camchain.yaml when there is one), a *.json or a *.yaml/*.yml file. A
// rig_config.json with several rigs gives the first one with more than one
// camera.
bool ReadRigReference(const std::string& path, RigDescription* rig,
                      std::string* error);

}  // namespace rig_calibrator
