// The truth of a synthetic rig as a calibration, the start of the tests that
// adjust from it: the true intrinsics, rig and rig poses, every image
// localized and every correspondence given as an inlier (the adjustment's
// pruning must find the wrong ones).
#pragma once

#include "src/calibration/pipeline.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace testing {

inline RigCalibration CalibrationAtTruth(const SyntheticRig& rig) {
  RigCalibration calibration;
  calibration.cameras = rig.truth.cameras;
  calibration.cam_from_rig = rig.truth.cam_from_rig;
  calibration.camera_calibrated.assign(rig.truth.cameras.size(), true);
  for (const Rigid3d& pose : rig.truth.rig_from_world) {
    calibration.rig_from_world.emplace_back(pose);
  }
  for (const RigImage& image : rig.dataset.images) {
    ImageResult result;
    result.localized = true;
    result.inlier_mask.assign(image.correspondences.size(), 1);
    calibration.images.push_back(result);
  }
  return calibration;
}

}  // namespace testing
}  // namespace rig_calibrator
