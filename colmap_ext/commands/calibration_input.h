// The calibration problem of `rig_calibrator [calibrate]`: the rig layout
// (cameras, framesets) of the rig images and their 2D-3D correspondences,
// either localized against a COLMAP map (database + model) or read from a
// correspondence file.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>
#include <unordered_set>

#include "colmap_ext/commands/calibrate_options.h"
#include "colmap_ext/io/calibration_summary.h"
#include "colmap_ext/io/rig_layout.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

// The images under --image_path, their cameras in --database_path and their
// correspondences from localizing them against `map`. The framesets are the
// database's frames if COLMAP's rig_configurator grouped the rig images
// (COLMAP >= 3.12), else found from the names. Prints the database's schema,
// the rig layout and the localization's progress. `rig_prior` (may be null)
// gets the known sensor_from_rig of the database rig of the rig cameras, if
// any. False with *error (naming the file or option) on failure.
bool LoadFromDatabase(const CalibrateOptions& options,
                      const colmap::Reconstruction& map, RigDataset* dataset,
                      RigLayout* layout, std::string* error,
                      KnownRigPrior* rig_prior = nullptr);

// The images and correspondences of --correspondences_path. Prints the rig
// layout.
bool LoadFromCorrespondences(const CalibrateOptions& options,
                             RigDataset* dataset, RigLayout* layout,
                             std::string* error);

// Adds the registered images of `map` with their cameras, poses and
// observations of map points, and every map point, to the dataset (for the
// final bundle adjustment's map observations).
// Returns the number of map images left out because their camera is a
// placeholder for a model newer than COLMAP 3.8 (`placeholder_cameras`), which
// this build cannot project.
int AddMapImages(
    const colmap::Reconstruction& map,
    const std::unordered_set<colmap::camera_t>& placeholder_cameras,
    RigDataset* dataset);

}  // namespace rig_calibrator
