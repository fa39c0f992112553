// Accuracy of a rig calibration against a reference (ground truth, or another
// tool's calibration such as Kalibr's, as in the paper's section 5.2).
//
// Extrinsics: the estimated rig frame may differ from the reference's (another
// reference camera, another tool's convention, a non-metric map), so the
// estimate is first aligned to the reference by a similarity
// rigref_from_rigest = (s, R, t):
//  - R: the rotation that best maps the estimated camera orientations to the
//    reference ones in the chordal L2 sense,
//      R = argmin sum_i |R_ref_i^T R_est_i - R|_F^2
//        = NearestRotation(sum_i R_ref_i^T R_est_i),
//    where R_x_i is the rotation of camera i's cam_from_rig. Orientations
//    are used rather than a Umeyama fit on camera centers because a rig is
//    small (0.1 m), so its centers constrain the rotation far less than its
//    camera orientations do (and do not constrain it at all for 2 cameras).
//  - s (align_scale only, for non-metric maps): with R fixed, the least
//    squares scale of the camera centers about their centroids (Umeyama's
//    scale for R), s = sum_i (c_ref_i - m_ref) . R (c_est_i - m_est) /
//    sum_i |c_est_i - m_est|^2 for >= 3 cameras; the ratio of the baseline
//    lengths for 2 cameras; 1 for a single camera.
//  - t = m_ref - s R m_est (the centroids coincide).
// With RigAlignment::kReferenceCamera the reference camera's orientation and
// center are matched exactly instead (s as above but about that camera's
// center): the errors of the other cameras are then relative to it.
//
// Intrinsics: the focal length and principal point are compared directly;
// distortion coefficients of different models are not compared, projections
// are: for a grid of reference pixels, the ray through the pixel (reference
// model) is projected with the estimated model and the pixel distance is
// measured. Rays where either model is outside its valid field of view (no
// exact inverse, or a folded mapping with a non-positive Jacobian
// determinant) are skipped and counted.
#pragma once

#include <colmap/base/camera.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

struct CameraError {
  double rotation_deg = 0;  // angle of R_est^T R_ref of cam_from_rig, aligned
  double center_error =
      0;  // camera center distance in the rig frame (map units)
  // |f_est - f_ref| / f_ref * 100; the mean over fx and fy when both models
  // have both, else that of the mean focal lengths.
  double focal_error_percent = 0;
  double principal_point_error_px = 0;
  // Over the projection grid, see above.
  double mean_projection_diff_px = 0, max_projection_diff_px = 0;
  int num_projection_samples = 0;  // grid rays compared
  int num_projection_skipped = 0;  // grid rays outside a valid field of view
};

struct CalibrationError {
  std::vector<CameraError> cameras;
  double scale = 1.0;  // the applied s (1 without align_scale)
  std::string error;   // empty on success; else why nothing was compared

  bool ok() const { return error.empty(); }
  double MaxRotationDeg() const;
  double MaxCenterError() const;
  double MaxFocalErrorPercent() const;
  double MaxPrincipalPointErrorPx() const;
  double MaxProjectionDiffPx() const;
};

enum class RigAlignment { kAllCameras, kReferenceCamera };

struct CompareOptions {
  bool align_scale = false;
  RigAlignment alignment = RigAlignment::kAllCameras;
  int reference_camera = 0;  // for kReferenceCamera
  // Grid of reference pixels for the projection difference.
  int grid_cols = 20;
  int grid_rows = 15;
};

// Compares intrinsics and cam_from_rig of an estimate with a reference (same
// number of cameras, in the same order). On bad input (sizes differ, invalid
// camera parameters) returns no cameras and a message in `error`.
CalibrationError CompareCalibrations(
    const std::vector<colmap::Camera>& reference_cameras,
    const std::vector<Rigid3d>& reference_cam_from_rig,
    const std::vector<colmap::Camera>& estimated_cameras,
    const std::vector<Rigid3d>& estimated_cam_from_rig,
    const CompareOptions& options);

// The same with all-camera alignment and the default grid.
CalibrationError CompareCalibrations(
    const std::vector<colmap::Camera>& reference_cameras,
    const std::vector<Rigid3d>& reference_cam_from_rig,
    const std::vector<colmap::Camera>& estimated_cameras,
    const std::vector<Rigid3d>& estimated_cam_from_rig, bool align_scale);

// Pixel distance between the projections of the same rays by two models
// (intrinsics only), over a grid_cols x grid_rows grid of pixel-cell centers
// of the reference image. Fills the projection fields of `error`.
void CompareProjections(const colmap::Camera& reference,
                        const colmap::Camera& estimate, int grid_cols,
                        int grid_rows, CameraError* error);

// The normalized ray (u, v, 1) of a pixel, polished by Newton steps on the
// model's own projection so that it reprojects to the pixel to ~1e-10 px.
// False outside the model's valid field of view.
bool UnprojectPixel(const colmap::Camera& camera, const Eigen::Vector2d& pixel,
                    Eigen::Vector2d* normalized);

// One row per camera (names[i] labels camera i; missing names become
// "cam<i>"): rotation (degrees), center error (map units), focal (%),
// principal point (px), projection difference mean/max (px); then the maxima
// and the applied scale.
std::string FormatCalibrationErrorTable(const CalibrationError& error,
                                        const std::vector<std::string>& names);

// {"scale": s, "cameras": [{"name", "rotation_deg", "center_error", ...}],
//  "max": {...}} for machine-readable reports.
nlohmann::json CalibrationErrorToJson(const CalibrationError& error,
                                      const std::vector<std::string>& names);

}  // namespace rig_calibrator
