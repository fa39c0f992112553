// Reads a COLMAP sparse model (the map) without letting COLMAP abort on bad
// input: COLMAP 3.8's Reconstruction::Read ends the process (LOG(FATAL),
// CHECK) on missing or malformed files. The checks here turn those cases into
// messages that name the file.
#pragma once

//
// Maps of COLMAP 3.12 - 4.1 are read too (see README, "COLMAP versions"):
// * Cameras of models COLMAP 3.8 does not know (ids 11-17, e.g. FISHEYE of
//   4.0) are held in the colmap::Reconstruction as placeholders, PINHOLE with
//   COLMAP's default focal length 1.2 max(width, height) and the principal
//   point at the image center, and listed in MapReadInfo with their real
//   model and parameters. Localizing rig images against a map needs its 3D
//   points and its images' descriptors, not its cameras' intrinsics; nothing
//   may project with a placeholder, and the output model gets the real
//   cameras back (RestoreNewerModelCameras).
// * rigs and frames files (COLMAP >= 3.12) are read and checked: every
//   registered image is in one frame, and its pose in images.* equals
//   sensor_from_rig * rig_from_world of its frame (COLMAP 4.x writes it so).
//   The image poses are then used as they are: localization needs no more of
//   the map's rigs.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>
#include <vector>

#include "colmap_ext/io/camera_records_io.h"

namespace rig_calibrator {

// What ReadMap found beyond what a COLMAP 3.8 model holds.
struct MapReadInfo {
  // The cameras of models COLMAP 3.8 does not know, as in the file; the map
  // holds placeholders for them.
  std::vector<CameraRecord> newer_model_cameras;
  bool has_rigs_frames = false;
  int num_rigs = 0;
  int num_multi_camera_rigs = 0;  // rigs with more than one camera
  int num_frames = 0;
  // Lines for the log, about the above.
  std::vector<std::string> notes;
  // What the user should fix in the map's files: repairs of inconsistencies
  // made in memory (map_consistency.h).
  std::vector<std::string> warnings;
};

// Reads the model in folder `path` (cameras, images, points3D as .bin, else
// .txt; rigs and frames if present). Fails with a message if the folder or a
// file is missing or unreadable, a binary file's records do not fit its size
// exactly, a camera model is unknown to every COLMAP up to 4.1 or has the
// wrong number of parameters, a text file does not parse, an id repeats, a
// camera or an image pose is invalid (map_consistency.h), the rigs and frames
// disagree with the images, or the model has no registered image or no 3D
// point. Observations and tracks that do not confirm each other are repaired
// in `map` and counted in info->warnings (map_consistency.h).
bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             MapReadInfo* info, std::string* error);
bool ReadMap(const std::string& path, colmap::Reconstruction* map,
             std::string* error);

// As ReadMap, but a model without registered images or 3D points is read
// too (e.g. the output model of a calibration from correspondences alone).
bool ReadModel(const std::string& path, colmap::Reconstruction* model,
               MapReadInfo* info, std::string* error);

// Rewrites the cameras file of the model written in `folder` (cameras.bin
// if `binary`, else cameras.txt) with the real records of `cameras` in place
// of their placeholders. No-op for an empty list.
bool RestoreNewerModelCameras(const std::string& folder, bool binary,
                              const std::vector<CameraRecord>& cameras,
                              std::string* error);

// The largest camera and image ids of a model (0 when it has none): new
// cameras, images, rigs and frames are numbered after them.
colmap::camera_t MaxCameraId(const colmap::Reconstruction& model);
colmap::image_t MaxImageId(const colmap::Reconstruction& model);

}  // namespace rig_calibrator
