// The cameras files of COLMAP models (cameras.bin, cameras.txt) with cameras
// of any model up to COLMAP 4.1, including the models COLMAP 3.8 does not know
// (ids 11-17), which its Reconstruction cannot hold.
//
// cameras.bin (little endian): u64 num_cameras, per camera u32 camera_id,
//   i32 model_id, u64 width, u64 height, f64 x num_params.
// cameras.txt: '#' comments, then per camera
//   CAMERA_ID MODEL_NAME WIDTH HEIGHT PARAMS[]
// The same in COLMAP 3.8 to 4.1.
#pragma once

#include <colmap/util/types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace rig_calibrator {

struct CameraRecord {
  colmap::camera_t camera_id = colmap::kInvalidCameraId;
  int model_id = -1;
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;
};

// Reads `path` (cameras.bin if `binary`, else cameras.txt). Fails naming the
// file (and line) for a truncated or malformed file, a model no COLMAP up to
// 4.1 has, or a parameter count that does not fit the model.
bool ReadCameraRecords(const std::string& path, bool binary,
                       std::vector<CameraRecord>* cameras, std::string* error);

// Writes the records in COLMAP's layout (text with 17 significant digits, as
// COLMAP writes them), through a temporary file renamed into place.
bool WriteCameraRecords(const std::string& path, bool binary,
                        const std::vector<CameraRecord>& cameras,
                        std::string* error);

}  // namespace rig_calibrator
