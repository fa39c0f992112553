// A copy of the calibration's database that lets COLMAP continue from the
// calibrated rig: the rig images' verified matches to the map images, taken
// from the 2D-3D correspondences the final adjustment kept. A rig keypoint
// that observes map point X is matched to the keypoint of every map image
// whose observation of X is in the map's track, so COLMAP's
// point_triangulator, mapper and bundle_adjuster see the rig images linked to
// the map as the calibration did.
#pragma once

#include <colmap/base/reconstruction.h>

#include <cstdint>
#include <string>

#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

struct DatabaseExportSummary {
  int num_rig_images = 0;       // with at least one exported match
  int num_image_pairs = 0;      // rig image - map image pairs written
  int64_t num_matches = 0;      // keypoint matches written
  int num_unmatched_rows = 0;   // correspondences without a database keypoint
  int num_cameras_updated = 0;  // rig cameras given the calibrated intrinsics
};

// Copies `database_path` (a COLMAP 3.8 database holding the map images and
// the rig images' keypoints) to `export_path`, a new file (refused if it
// exists or is the input), through a temporary sibling renamed into place.
// In the copy, for every used rig image and every map image it shares
// inlier correspondences with (through `map`'s tracks), the pair's matches
// and two-view geometry are replaced by those matches, with config
// CALIBRATED and the relative pose of the calibration (E = [t]x R, unit t).
// A correspondence's rig keypoint is the image's database keypoint at its 2D
// point (within 1e-3 px). Every rig camera whose images share one database
// camera of their own gets the calibrated model and parameters there. False
// with *error (nothing written) on failure.
bool ExportDatabaseWithRigMatches(const std::string& database_path,
                                  const std::string& export_path,
                                  const colmap::Reconstruction& map,
                                  const RigDataset& dataset,
                                  const RigCalibration& calibration,
                                  DatabaseExportSummary* summary,
                                  std::string* error);

}  // namespace rig_calibrator
