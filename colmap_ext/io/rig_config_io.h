// The rig configuration files of COLMAP:
//
// * rig_config.json of COLMAP >= 3.12 `rig_configurator` (a list of rigs):
//     [{"cameras": [
//        {"image_prefix": "cam0/", "ref_sensor": true,
//         "camera_model_name": "OPENCV_FISHEYE", "camera_params": [...]},
//        {"image_prefix": "cam1/",
//         "cam_from_rig_rotation": [w, x, y, z],
//         "cam_from_rig_translation": [x, y, z],
//         "camera_model_name": "OPENCV_FISHEYE", "camera_params": [...]}]}]
//   The reference sensor has no pose; pose fields and intrinsics fields are
//   each optional but come in pairs.
//
// * the --rig_config_path file of COLMAP 3.8 `rig_bundle_adjuster`
//   (src/exe/sfm.cc, ReadCameraRigConfig):
//     [{"ref_camera_id": 1,
//       "cameras": [{"camera_id": 1, "image_prefix": "cam0/",
//                    "rel_qvec": [w, x, y, z], "rel_tvec": [x, y, z]}, ...]}]
//   rel_qvec/rel_tvec are cam_from_rig; camera ids are those of the model the
//   file goes with. Run it with --estimate_rig_relative_poses 0, otherwise
//   COLMAP re-estimates the poses from the images and ignores the file's.
#pragma once

#include <colmap/base/reconstruction.h>

#include <string>
#include <vector>

#include "colmap_ext/io/rig_description.h"

namespace rig_calibrator {

// Cameras without intrinsics or cam_from_rig are written without those
// fields, which rig_configurator then takes from a model or the database.
bool WriteRigConfigJson(const std::string& path, const RigDescription& rig,
                        std::string* error);

// Reads every rig of a rig_config.json. Camera names are the image prefixes
// without a trailing '/'; intrinsics have width and height 0. Fails on
// missing prefixes, not exactly one reference sensor, a pose on the reference
// sensor, half-given pairs, unknown camera models or wrong parameter counts.
bool ReadRigConfigJson(const std::string& path,
                       std::vector<RigDescription>* rigs, std::string* error);

// Writes the calibrated cameras (those with intrinsics, whose camera id is
// set, and a cam_from_rig); cameras without them are left out, so that
// COLMAP treats their images as independent images.
bool WriteRigBundleAdjusterConfig(const std::string& path,
                                  const RigDescription& rig,
                                  std::string* error);

// What COLMAP 3.8 rig_bundle_adjuster will make of the file written by
// WriteRigBundleAdjusterConfig for `model`, found by grouping the model's
// registered images exactly as ReadCameraRigConfig does: an image belongs to
// every camera whose prefix it contains anywhere in its name, its snapshot key
// is the name after the last occurrence of the prefix, and only snapshots
// with an image of the reference camera are used.
struct RigBundleAdjusterGrouping {
  int num_snapshots = 0;              // used snapshots
  int num_multi_image_snapshots = 0;  // of them, with two images or more
  // Conditions on which COLMAP would abort (a CHECK in CameraRig): a snapshot
  // with an image of a camera outside the rig, with more images than the rig
  // has cameras, or with one image twice.
  std::vector<std::string> problems;
};
RigBundleAdjusterGrouping PredictRigBundleAdjusterGrouping(
    const RigDescription& rig, const colmap::Reconstruction& model);

}  // namespace rig_calibrator
