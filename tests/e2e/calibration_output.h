// Reading a calibration output folder for the e2e checks
// (check_calibration_outputs.cc): the COLMAP model and
// calibration_summary.json, pose differences and the check report.
#pragma once

#include <colmap/base/reconstruction.h>

#include <optional>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

// Prints "[check] <name>: <details>: ok|FAILED" and counts failures.
void Report(const std::string& name, const std::string& details, bool ok);
// The failures Report counted.
int NumFailedChecks();
// Three significant digits.
std::string Number(double value);
// Prints "[check] ERROR: <message>" and exits with status 2.
[[noreturn]] void Die(const std::string& message);

// The largest differences over pairs of poses.
struct PoseDifference {
  double rotation_rad = 0;
  double translation = 0;
  void Max(const Rigid3d& a, const Rigid3d& b);
  // "rotation R rad, translation T<translation_unit>".
  std::string Text(const std::string& translation_unit = "") const;
};

// |a - b| / max(1, |a|).
double RelativeDifference(double a, double b);
// cam_from_world of a model image.
Rigid3d ImagePose(const colmap::Image& image);

// One camera of calibration_summary.json.
struct SummaryCamera {
  std::string name;
  std::string image_prefix;
  bool calibrated = false;
  colmap::Camera camera;
  std::optional<Rigid3d> cam_from_rig;
  int num_used = 0;
};

struct Summary {
  std::string method;
  std::string reference_camera;
  int num_framesets_used = 0;
  std::vector<SummaryCamera> cameras;
};

struct Output {
  std::string folder;
  colmap::Reconstruction model;
  Summary summary;
};

// Reads the COLMAP model (binary or text) in `folder`; exits (Die) if there
// is none.
colmap::Reconstruction ReadModel(const std::string& folder);

// Reads the model and calibration_summary.json of an output folder; exits
// (Die) if they cannot be read.
Output ReadOutput(const std::string& folder);

// The largest pixel distance between `a` and `b` over a grid of pixels:
// each pixel is lifted to a ray with `a` and projected with `b`.
double MaxProjectionDifferencePx(const colmap::Camera& a,
                                 const colmap::Camera& b);

// Kalibr has an exact equivalent of these COLMAP models (camchain_io.h).
bool MapsExactlyToKalibr(const colmap::Camera& camera);

// The model's camera of the rig camera with `image_prefix`: the camera of
// its registered images (which must all share it).
std::optional<colmap::camera_t> ModelCameraOfPrefix(
    const colmap::Reconstruction& model, const std::string& image_prefix,
    int* num_images);

}  // namespace rig_calibrator
