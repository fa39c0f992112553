// The camera model ids of every COLMAP version up to 4.1, including those
// COLMAP 3.8 does not know (ids 11-17), so that maps and databases of newer
// COLMAP can be read and their cameras named in messages.
#pragma once

#include <string>

namespace rig_calibrator {

// The largest model id of COLMAP 3.8 (THIN_PRISM_FISHEYE).
inline constexpr int kMaxColmap38CameraModelId = 10;

// COLMAP's name of the model (e.g. 15 -> "FISHEYE"), "UNKNOWN" if no COLMAP
// up to 4.1 has it.
std::string ColmapCameraModelName(int model_id);

// The number of parameters of the model; -1 if no COLMAP up to 4.1 has it.
int ColmapCameraModelNumParams(int model_id);

// The model id of a name (e.g. "EUCM" -> 16); -1 if unknown.
int ColmapCameraModelIdFromName(const std::string& name);

// "FISHEYE (model id 15, COLMAP >= 4.0)" for messages.
std::string DescribeColmapCameraModel(int model_id);

}  // namespace rig_calibrator
