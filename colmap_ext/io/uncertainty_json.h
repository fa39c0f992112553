// The uncertainty of a calibration (src/calibration/calibration_uncertainty.h)
// in the outputs: the "uncertainty" of every camera and the top-level
// "uncertainty_method" of calibration_summary.json, the comment lines of
// camchain.yaml, and the terminal lines of the result. Pixels are COLMAP's;
// standard deviations do not depend on the pixel convention.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "colmap_ext/io/rig_description.h"
#include "src/calibration/calibration_uncertainty.h"

namespace rig_calibrator {

// Per camera c of root["cameras"] (the dataset's order) its
// "uncertainty": {residual_scale_px, params_stddev (0: held, null:
// undetermined; at least the model choice's spread), model_choice_stddev
// (that spread per parameter where it is the larger, else 0,
// src/calibration/model_choice_spread.h; only when the choice on the
// adjusted rig found another model as good),
// rotation_stddev_deg (sqrt of the trace of the rotation
// vector's covariance), rotation_axis_stddev_deg, translation_stddev,
// center_in_rig_stddev, between_framesets_factor (max over the parameters
// of the between-framesets sigma over the noise sigma; null when not
// computed), projection_stddev_px: {median, max, max_at, depth,
// grid: {cols, rows, values (row-major, cell centres, null where the model
// does not unproject)}}}, null for a camera without one; and
// root["uncertainty_method"] (what was computed, or why not). Never NaN.
void AddUncertaintyJson(const CalibrationUncertainty& uncertainty,
                        nlohmann::ordered_json* root);

// Comment lines (without "# ") for each calibrated camera of `rig`
// (RigDescriptionCamera::comments), in the dataset's camera order.
void AddUncertaintyComments(const CalibrationUncertainty& uncertainty,
                            RigDescription* rig);

// A camera whose between-framesets sigma exceeds its noise sigma by more
// than this gets a note in its terminal line: below it the two agree within
// what a handful of framesets can tell.
constexpr double kBetweenFramesetsNoteFactor = 1.5;

// The lines of the terminal result: per camera sigma of the focal length(s),
// principal point, rotation and centre, the projection uncertainty, and the
// model choice's spread when the first two include it.
std::vector<std::string> UncertaintyLines(
    const std::vector<std::string>& camera_names,
    const std::vector<colmap::Camera>& cameras,
    const CalibrationUncertainty& uncertainty);

}  // namespace rig_calibrator
