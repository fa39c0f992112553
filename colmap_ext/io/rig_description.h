// A rig as the exchange formats describe it (COLMAP's rig_config.json and
// rig_bundle_adjuster config, Kalibr's camchain.yaml): per camera its
// intrinsics and cam_from_rig, with the rig frame being the reference
// camera's frame.
#pragma once

#include <colmap/base/camera.h>

#include <optional>
#include <string>
#include <vector>

#include "src/calibration/camera_timing.h"
#include "src/geometry/rigid3d.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

struct RigDescriptionCamera {
  std::string name;          // e.g. "cam0"
  std::string image_prefix;  // e.g. "cam0/"
  // Intrinsics, when known. Width and height are 0 when the format has none
  // (rig_config.json). The camera id is that of the output model, when there
  // is one.
  std::optional<colmap::Camera> camera;
  // Relative to the reference camera; unknown for a camera that could not be
  // calibrated (or that a file leaves out).
  std::optional<Rigid3d> cam_from_rig;
  // Lines written as comments with the camera in the formats that allow
  // them (camchain.yaml), e.g. the uncertainty (uncertainty_json.h).
  std::vector<std::string> comments;
  // The capture timing (camera_timing.h), when estimated: delta_c relative
  // to the frameset times; and the constant removed from the camera's own
  // numeric names before grouping them into framesets (seconds,
  // timestamp_offsets.h), so that the camera's capture time on the
  // reference camera's clock is its own timestamp + delta_c -
  // timestamp_offset_s (camchain's timeshift_cam_imu).
  std::optional<CameraTiming> timing;
  double timestamp_offset_s = 0;
};

struct RigDescription {
  std::vector<RigDescriptionCamera> cameras;
  int reference_camera = 0;  // its cam_from_rig is the identity
};

// The calibrated rig of `calibration`, re-expressed so that the rig frame is
// exactly the reference camera's frame: cam_from_ref = cam_from_rig *
// (ref_from_rig)^-1 (the identity for the reference camera whatever rounding
// the solver left). Cameras with camera_calibrated false have neither
// intrinsics nor cam_from_rig. `image_prefixes` (one per camera) may be empty:
// the prefix is then the camera's name followed by '/'. Requires
// ValidateCalibration (src/rig/rig_dataset.h).
RigDescription DescribeCalibratedRig(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes);

}  // namespace rig_calibrator
