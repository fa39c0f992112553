// The tables of report.html, as HTML fragments built from
// calibration_summary.json (keys of ISSUE12_SHARED's contract that are absent
// are shown as "not computed"): the intrinsics with their standard deviations,
// the camera poses in the rig, the automatic model choice, the model validity
// and the diagnostics. Text is escaped; numbers have 4 significant digits.
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "colmap_ext/report/report_json.h"

namespace rig_calibrator {

// The HTML of "not computed", with why (`reason`, escaped).
std::string NotComputedHtml(const std::string& reason);

// Per camera and parameter (COLMAP's order and names): value ± params_stddev
// of "uncertainty", which parameters were refined ("refined").
std::string IntrinsicsTableHtml(const ReportJson& summary);

// Per camera: the centre in the rig ± center_in_rig_stddev, the rotation from
// the reference camera ± rotation_stddev_deg, the translation ±
// translation_stddev, images localized / used, inliers, RMS.
std::string PosesTableHtml(const ReportJson& summary);

// The candidates of "model_choice" per camera that has it.
std::string ModelChoiceHtml(const ReportJson& summary);

// Per camera the "validity" of its model over the whole image.
std::string ValidityTableHtml(const ReportJson& summary);

// Every line of "diagnostics", coloured by its level (error, warning, info;
// other lines are notes).
std::string DiagnosticsListHtml(const ReportJson& summary);

// cam_from_rig of a summary camera (absent or malformed: none).
std::optional<Eigen::Quaterniond> CamFromRigRotation(const ReportJson& camera);
std::optional<Eigen::Vector3d> CamFromRigTranslation(const ReportJson& camera);

// A 3-vector of numbers at `key` (absent or malformed: none).
std::optional<Eigen::Vector3d> Vector3At(const ReportJson& node,
                                         const char* key);

}  // namespace rig_calibrator
