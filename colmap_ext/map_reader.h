// Reads a COLMAP sparse model (the map) without letting COLMAP abort on bad
// input: COLMAP 3.8's Reconstruction::Read ends the process (LOG(FATAL),
// CHECK) on missing or malformed files. The checks here turn those cases into
// messages that name the file.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>

namespace rig_calibrator {

// Reads the model in folder `path` (cameras, images, points3D as .bin, else
// .txt). Fails with a message if the folder or a file is missing, a binary
// file's record count does not fit its size, a text file does not parse, or
// the model has no registered image or no 3D point.
bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             std::string* error);

}  // namespace rig_calibrator
