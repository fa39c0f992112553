// The output of a calibration: a COLMAP 3.8 model holding the map and the
// registered rig images, plus the rig in every exchange format, written into
// the output folder completely or not at all.
//
// Files in the output folder:
//   cameras, images, points3D (.bin or .txt)   the COLMAP 3.8 model
//   rigs, frames (.bin or .txt)                the rig for COLMAP >= 3.12
//   rig_config.json                            COLMAP >= 3.12 rig_configurator
//   rig_bundle_adjuster_config.json            COLMAP 3.8 rig_bundle_adjuster
//   camchain.yaml                              Kalibr
//   calibration_summary.json                   the summary
//   timings.json                               wall time per stage (the only
//                                              file that changes between runs
//                                              of the same input)
//   correspondences.txt                        the 2D-3D correspondences used
//   report.html                                the visual report, when the
//                                              caller's finish_folder writes
//                                              it (the calibrate command)
#pragma once

#include <colmap/base/reconstruction.h>

#include <functional>
#include <string>
#include <unordered_set>
#include <vector>

#include "colmap_ext/io/calibration_summary.h"
#include "colmap_ext/io/camera_records_io.h"
#include "colmap_ext/io/model_errors.h"
#include "colmap_ext/io/rigs_frames_io.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

inline constexpr char kRigConfigFile[] = "rig_config.json";
inline constexpr char kRigBundleAdjusterConfigFile[] =
    "rig_bundle_adjuster_config.json";
inline constexpr char kCamchainFile[] = "camchain.yaml";
inline constexpr char kSummaryFile[] = "calibration_summary.json";
inline constexpr char kTimingsFile[] = "timings.json";
inline constexpr char kCorrespondencesFile[] = "correspondences.txt";

struct RigModel {
  colmap::Reconstruction model;
  // The rig's camera ids, cam_from_rig and frames in `model` (rig frame =
  // the reference camera's frame).
  ModelRig rig;
  // Per dataset image: its image id, or kInvalidImageId if not registered.
  std::vector<colmap::image_t> image_ids;
  // The map images' observations: errors recomputed in the input map and in
  // `model`, and the observations the final adjustment rejected (dropped).
  ReprojectionStats map_input_errors, map_output_errors;
  int64_t num_dropped_map_observations = 0;
};

// The map (with the refined points of `calibration`, if any) plus:
// * one camera per rig camera, ids after the map's, with the calibrated
//   intrinsics (the dataset's for cameras that were not calibrated);
// * every image that is used, of a calibrated camera and of a frameset with a
//   rig pose, registered with cam_from_world = cam_from_rig * rig_from_world,
//   image id = (the map's largest image id) + 1 + (its dataset index);
// * as the image's points2D all its correspondences' 2D points; those that are
//   inliers and whose point3D_id is a map point observe it (one observation
//   per map point and image);
// * the map images at the calibration's map poses and intrinsics (if it has
//   map results), without the map observations it rejected;
// * every point's error recomputed from the final model (model_errors.h),
//   observations behind their camera dropped.
// Fails, leaving `rig_model` unspecified, if the calibration does not match
// the dataset, intrinsics are invalid, a refined point or a rig image name is
// already in the map, or the ids overflow.
// Map images of `placeholder_map_cameras` (models newer than COLMAP 3.8, held
// as placeholders by ReadMap) are left out of the recomputed errors.
bool BuildRigModel(
    const colmap::Reconstruction& map, const RigDataset& dataset,
    const RigCalibration& calibration, RigModel* rig_model, std::string* error,
    const std::unordered_set<colmap::camera_t>& placeholder_map_cameras = {});

struct RigOutputOptions {
  std::string output_type = "BIN";  // "BIN" or "TXT", as COLMAP's
  bool overwrite = false;           // replace a non-empty output folder
  // The run's inputs (database, image path, map, correspondence file): the
  // output folder must not overlap any of them.
  std::vector<std::string> input_paths;
  // Map cameras of models COLMAP 3.8 does not know (MapReadInfo), written in
  // place of their placeholders.
  std::vector<CameraRecord> newer_model_map_cameras;
  // Called last on the temporary folder holding every file above, e.g. to
  // write report.html from them (colmap_ext/report/report_page.h, which
  // depends on this library); its failure fails the whole output.
  std::function<bool(const std::string& folder, std::string* error)>
      finish_folder;
};

// Builds the model (BuildRigModel) and writes every file above into
// `output_path` through a temporary sibling folder renamed into place; on any
// failure nothing is left behind. `camera_prefixes` are the cameras' image
// prefixes (empty: name + "/"). Notes on the exports (approximated Kalibr
// cameras, what COLMAP's rig tools will make of the configs) are appended to
// the summary's diagnostics in the file and to `notes` (may be null).
bool WriteRigOutput(const std::string& output_path,
                    const colmap::Reconstruction& map,
                    const RigDataset& dataset,
                    const RigCalibration& calibration,
                    const std::vector<std::string>& camera_prefixes,
                    const CalibrationSummary& summary,
                    const RigOutputOptions& options,
                    std::vector<std::string>* notes, std::string* error);

}  // namespace rig_calibrator
