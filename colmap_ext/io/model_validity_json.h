// The "validity" and "model_choice" entries of a camera in
// calibration_summary.json (CameraModelReport, src/calibration/
// camera_model_report.h):
//   "validity": {"valid", "monotonic", "max_roundtrip_error_px" (null if not
//     finite), "fold_radius_px" (null: no fold), "fold_angle_deg",
//     "corner_radius_px", "fits_data" (the radial residual check),
//     "radial_residual_rings" (when evaluated): [{"min_radius_px",
//     "max_radius_px", "num_points", "num_images", "mean_radial_px",
//     "standard_error_px" (clustered by image), "z", "z_threshold"}],
//     "systematic_floor_px" (the map's own systematic level, which a ring's
//     |mean| must exceed significantly; 0 without map images),
//     "suggested_model" (null: none), "message"}
//   "model_choice" (cameras whose model was "auto" only): {"chosen",
//     "reason", "uncertain" (the choice failed a check; warned),
//     "candidates": [{"model", "valid", "heldout_rms_px",
//     "train_rms_px", "num_params", "num_inliers", "chosen",
//     "as_good_as_best" (within the rule's standard errors of the best; the
//     others of these set the model choice's spread in the uncertainty),
//     "note"}]}
#pragma once

#include <nlohmann/json.hpp>

#include "colmap_ext/io/calibration_summary.h"
#include "src/calibration/pipeline_report.h"

namespace rig_calibrator {

// Copies the pipeline's per-camera model reports into the summary.
void AttachCameraModelReports(const PipelineReport& report,
                              CalibrationSummary* summary);

// Adds the camera's "validity" (when checked) and "model_choice" (when
// chosen) to its JSON node.
void AddCameraModelJson(const CameraModelReport& report,
                        nlohmann::ordered_json* node);

}  // namespace rig_calibrator
