// Kalibr's camera chain file (camchain.yaml), read by many robotics tools:
//
//   cam0:
//     camera_model: pinhole
//     intrinsics: [fu, fv, pu, pv]
//     distortion_model: radtan        # or equidistant, fov, none
//     distortion_coeffs: [k1, k2, r1, r2]
//     resolution: [width, height]
//     rostopic: /cam0/image_raw
//   cam1:
//     T_cn_cnm1:                      # cam1_from_cam0, 4x4
//     - [r11, r12, r13, t1]
//     ...
//
// Kalibr puts the center of the top-left pixel at (0, 0) (OpenCV), COLMAP at
// (0.5, 0.5): pu = cx - 0.5, pv = cy - 0.5. T_cn_cnm1 maps camera n-1's
// coordinates to camera n's: x_n = R x_{n-1} + t, i.e. cam_n_from_cam_{n-1}.
//
// COLMAP 3.8 models and their Kalibr equivalents (pinhole projection, same
// focal lengths and principal point):
//   SIMPLE_PINHOLE, PINHOLE       -> radtan [0, 0, 0, 0]                exact
//   SIMPLE_RADIAL, RADIAL, OPENCV -> radtan [k1, k2, p1, p2]            exact
//   FULL_OPENCV                   -> radtan, exact if k3..k6 are 0,
//                                    else a least-squares fit
//   OPENCV_FISHEYE, SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE
//                                 -> equidistant [k1, k2, k3, k4]       exact
//   FOV                           -> fov [omega]                        exact
//   THIN_PRISM_FISHEYE            -> equidistant, exact if p1, p2, sx1, sy1
//                                    are 0, else a least-squares fit
// Kalibr's equidistant model is OpenCV's fisheye model, as is COLMAP's
// OPENCV_FISHEYE; its fov model is the Devernay-Faugeras model of COLMAP's
// FOV. A fit keeps the focal lengths and principal point and fits the
// distortion coefficients to the COLMAP model's distortion over a grid of
// pixels (it is linear in them); its maximum error over the grid, in pixels,
// is written next to the camera in the file. Kalibr's omni, ds and eucm
// models are never written (no COLMAP 3.8 model is one of them) and are
// refused when read.
//
// Capture timing (camera_timing.h), written per camera only when estimated:
//   timeshift_cam_imu: s       Kalibr's name and sign, t_imu = t_cam + shift,
//                              with the reference camera in the IMU's place:
//                              t_ref = t_cam + timeshift_cam_imu, t_cam the
//                              camera's own image timestamp, t_ref the time
//                              on the reference camera's clock at which the
//                              image was taken (0 for the reference camera);
//                              = delta_c - the constant removed from the
//                              camera's names to group them (seconds)
//   line_delay: s/row          Kalibr's rolling-shutter line delay (row v is
//                              taken at t_ref + line_delay * v), only when
//                              estimated
// and three fields Kalibr has not (tools that read Kalibr ignore them):
//   timeshift_cam_imu_sigma    standard deviation of timeshift_cam_imu, s
//   line_delay_sigma           standard deviation of line_delay, s/row
//   timing_source              "measured after calibration" (lower bounds of
//                              the offsets, capture_timing.h) or "estimated
//                              in the adjustment"
// Read back into RigDescriptionCamera::timing (time offset =
// timeshift_cam_imu, timestamp_offset_s 0); a sigma or source without its
// value, or a value that is not a finite number, is refused.
#pragma once

#include <colmap/base/camera.h>

#include <string>
#include <vector>

#include "colmap_ext/io/rig_description.h"

namespace rig_calibrator {

struct KalibrCamera {
  std::string camera_model = "pinhole";
  std::vector<double> intrinsics;  // [fu, fv, pu, pv], Kalibr's pixels
  std::string distortion_model;    // radtan, equidistant, fov or none
  std::vector<double> distortion_coeffs;
  int width = 0;
  int height = 0;
  // False when the distortion is a least-squares fit of the COLMAP model's.
  bool exact = true;
  double max_fit_error_px = 0;  // of the fit, over the image
};

// The Kalibr equivalent of a COLMAP camera (see the table above). Fails for
// a camera without image size or whose distortion cannot be fitted.
bool ColmapToKalibrCamera(const colmap::Camera& camera, KalibrCamera* kalibr,
                          std::string* error);

// The COLMAP camera of a Kalibr pinhole camera: radtan -> OPENCV,
// equidistant -> OPENCV_FISHEYE, fov -> FOV, none -> PINHOLE.
bool KalibrToColmapCamera(const KalibrCamera& kalibr, colmap::Camera* camera,
                          std::string* error);

// Writes the rig's calibrated cameras (those with intrinsics and
// cam_from_rig), in rig order, as cam0, cam1, ...; cameras that are not
// calibrated are left out (with a comment). One note per approximated or
// left-out camera is appended to `notes` (may be null), for the summary.
bool WriteCamchainYaml(const std::string& path, const RigDescription& rig,
                       std::vector<std::string>* notes, std::string* error);

// Reads cam0, cam1, ... until the first missing index. The cameras are named
// cam0, cam1, ... (no image prefix), the rig frame is cam0's.
bool ReadCamchainYaml(const std::string& path, RigDescription* rig,
                      std::string* error);

}  // namespace rig_calibrator
