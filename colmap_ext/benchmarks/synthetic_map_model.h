// The inputs of a calibration from correspondences against a map, from a
// synthetic rig with map images (synthetic_rig.h, num_map_images > 0): the
// map as a COLMAP model and the rig's correspondences renumbered to that
// model's point ids, as `rig_calibrator --correspondences_path ...
// --input_path ...` reads them. For tests and the whole-pipeline fuzz target.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>
#include <vector>

#include "colmap_ext/io/correspondence_io.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

struct SyntheticMapModel {
  // Camera 1 (the map camera), images 1..M (the map images, their
  // observations as points2D in order), points 1..N (every map point that a
  // map image observes, in the order of first observation).
  colmap::Reconstruction map;
  // Every rig image's correspondences; point3D_id is the map model's id of
  // the point, or -1 for a point the map does not hold.
  std::vector<ImageCorrespondences> correspondences;
};

// Needs rig.dataset.map_images (num_map_images > 0).
SyntheticMapModel MakeSyntheticMapModel(const SyntheticRig& rig);

// Writes `model` into `folder`: correspondences.txt and the map as sparse/
// (binary if `binary`, else text). False with *error if a file cannot be
// written.
bool WriteSyntheticMapModel(const SyntheticMapModel& model,
                            const std::string& folder, bool binary,
                            std::string* error);

}  // namespace rig_calibrator
