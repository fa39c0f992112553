// What the pipeline found out about each camera's COLMAP model: whether the
// final model is valid over the whole image (model_validity.h) and, for a
// camera whose model was chosen automatically, the candidates and why one won
// (model_selection.h). One entry per dataset camera in
// PipelineReport::camera_models.
#pragma once

#include <optional>

#include "src/calibration/model_selection.h"
#include "src/calibration/model_validity.h"

namespace rig_calibrator {

struct CameraModelReport {
  // Of the final intrinsics; empty for a camera that was not calibrated.
  std::optional<ModelValidity> validity;
  // Only for a camera whose model was "auto".
  std::optional<ModelChoice> choice;
};

}  // namespace rig_calibrator
