// Capture timing after a calibration (pipeline step after the final bundle
// adjustment): each camera's capture-time offset delta_c measured from the
// rig images' own poses, and a warning when the cameras were not
// synchronized, since the calibration assumes that every frameset was taken
// at one instant.
//
// Runs only when the dataset has frameset times (RigDataset::
// frameset_times_s) and at least two cameras are calibrated.
//
// Poses. Every used rig image gets a full cam_from_world of its own: its
// camera's calibrated intrinsics held fixed, a pose refinement of that image
// alone (COLMAP's RefineAbsolutePose, reprojection error under a Cauchy loss
// of scale 1 px) on its final-BA inlier correspondences (against the refined
// map points when the adjustment moved them), started from the
// calibration's cam_from_rig * rig_from_world[f]; then its inliers are
// selected again as the correspondences within inlier_max_error_px of that
// pose and it is refined on them (twice). Images with fewer than
// min_inliers such inliers get none. The start is the rig's, the minimum is the
// image's own evidence: with an offset delta_c the image was taken where the
// rig was at t_f + delta_c, and its pose moves there. (The default method's
// single-image localizations are 1D radial poses without the forward
// translation, so they are not used.)
//
// Offsets. EstimateTimeOffsets (time_offset_estimation.h) on these poses and
// the frameset times: per camera delta_c, sigma, observable, diagnosis.
//
// Significance. A camera is named in the warning `unsynchronized_cameras`
// when its offset is observable and
//   |delta_c| > 3 sigma(delta_c)                      (measured, not noise),
//   |delta_c| > min_offset_s                          (1 ms floor),
//   omega_rig |delta_c| > sigma_rot,c                 (it matters),
// omega_rig the rig's median angular speed between consecutive posed
// framesets, angle(R_{f+1} R_f^T) / (t_{f+1} - t_f), and sigma_rot,c the
// calibration's own rotation sigma of camera c's cam_from_rig (calibration_
// uncertainty.h; the test is skipped when it was not computed). Why these:
// omega_rig |delta_c| is how far camera c's pose in a typical frameset is
// from the synchronized rig's; the adjustment absorbs it into cam_from_rig
// and the intrinsics, so a bias of that order is hidden in the result, and
// it is worth a warning when it exceeds the uncertainty the calibration
// reports. The floor: sigma(delta_c) covers the localization noise, not the
// trajectory interpolation's error or errors shared by a frameset (the
// map's, exposure, rolling shutter readout), so sub-millisecond offsets are
// not told apart from those; a hardware-triggered rig is synchronized to
// well below 1 ms.
//
// Accuracy. With the true intrinsics the offsets match the truth within a
// few sigma (capture_timing_test.cc). With intrinsics estimated from the same
// unsynchronized framesets they absorb part of the rig's motion and the
// images' own poses follow the rig: on ring5 with offsets in +-50 ms the
// measured offsets were 1.7-7 times too small (docs/time_model.md), so they
// are lower bounds, though still significant.
#pragma once

#include <string>
#include <vector>

#include "src/calibration/time_offset_estimation.h"

namespace rig_calibrator {

struct RigDataset;
struct RigCalibration;
struct CalibrationUncertainty;

struct CaptureTimingOptions {
  // Correspondences within this reprojection error of the image's own pose
  // are its inliers (re-selected: see capture_timing.cc); 8 sigma of 0.5 px
  // noise, below the distances of most wrong matches.
  double inlier_max_error_px = 4.0;
  // Images with fewer such inliers get no pose of their own.
  int min_inliers = 15;
  // The 1 ms floor of the significance test (see the top of the file).
  double min_offset_s = 1e-3;
  double min_offset_sigmas = 3.0;
  TimeOffsetOptions time_offsets;
};

struct CaptureTiming {
  // False when the step did not apply (no frameset times, fewer than two
  // calibrated cameras): nothing below is set and no output mentions it.
  bool computed = false;
  // Non-empty when the step applied but the offsets could not be estimated
  // (e.g. too few framesets with a reference pose): why.
  std::string error;
  // Per dataset camera (empty with an error).
  std::vector<CameraTimeOffset> offsets;
  std::vector<bool> significant;
  int num_image_poses = 0;  // images with a pose of their own
  double rig_angular_speed_rad_s = 0;  // omega_rig (see the top)
};

// The significance test above for one camera; rotation_sigma_rad <= 0 or
// not finite skips the "it matters" part.
bool OffsetIsSignificant(const CameraTimeOffset& offset,
                         double rig_angular_speed_rad_s,
                         double rotation_sigma_rad,
                         const CaptureTimingOptions& options);

// The median of angle(R_{f+1} R_f^T) / (t_{f+1} - t_f) over consecutive
// framesets that both have a rig pose; 0 without any.
double RigAngularSpeed(const std::vector<double>& frameset_times_s,
                       const RigCalibration& calibration);

// The step described at the top, after the final bundle adjustment and the
// uncertainty (whose rotation sigmas it uses; default-constructed: none).
// Requires ValidateCalibration (src/rig/rig_dataset.h).
CaptureTiming MeasureCaptureTiming(const RigDataset& dataset,
                                   const RigCalibration& calibration,
                                   const CalibrationUncertainty& uncertainty,
                                   const CaptureTimingOptions& options);

// One line for the terminal, e.g. "capture-time offsets against cam0: cam1
// +48.20 +- 0.31 ms (unsynchronized), cam2 not observable (...)", or why they
// were not measured. `camera_names` per dataset camera.
std::string CaptureTimingLine(const std::vector<std::string>& camera_names,
                              int reference_camera,
                              const CaptureTiming& timing);

}  // namespace rig_calibrator
