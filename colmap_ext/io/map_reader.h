// Reads a COLMAP sparse model (the map) without letting COLMAP abort on bad
// input: COLMAP 3.8's Reconstruction::Read ends the process (LOG(FATAL),
// CHECK) on missing or malformed files. The checks here turn those cases into
// messages that name the file.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>

namespace rig_calibrator {

// Reads the model in folder `path` (cameras, images, points3D as .bin, else
// .txt). Fails with a message if the folder or a file is missing or
// unreadable, a binary file's records do not fit its size exactly, a camera
// model is unknown to COLMAP 3.8 or has the wrong number of parameters, a text
// file does not parse, an id repeats, images, cameras and points refer to each
// other inconsistently, or the model has no registered image or no 3D point.
bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             std::string* error);

// The largest camera and image ids of a model (0 when it has none): new
// cameras, images, rigs and frames are numbered after them.
colmap::camera_t MaxCameraId(const colmap::Reconstruction& model);
colmap::image_t MaxImageId(const colmap::Reconstruction& model);

}  // namespace rig_calibrator
