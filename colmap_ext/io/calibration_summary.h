// The machine-readable summary of a calibration (calibration_summary.json):
// per camera the model, parameters, cam_from_rig and how well the images
// support them; globally the method, the units, diagnostics and timings.
#pragma once

#include <colmap/base/camera.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "src/calibration/rig_dataset.h"
#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

struct CameraSummary {
  std::string name;
  std::string image_prefix;
  bool calibrated = false;
  colmap::Camera camera;  // model, size and parameters (COLMAP pixels)
  std::optional<Rigid3d> cam_from_rig;
  int num_images = 0;
  int num_localized = 0;  // images with a pose of their own
  int num_used = 0;       // images in the final calibration
  int64_t num_inliers = 0;
  // Root mean square over the inliers of all used images.
  double radial_rms_px = 0;
  double rms_px = 0;
};

// The map images' observations, reprojection errors recomputed in the input
// map and in the output model (pixels).
struct MapImagesSummary {
  double input_mean_error_px = 0, output_mean_error_px = 0;
  double input_max_error_px = 0, output_max_error_px = 0;
  int64_t num_input_observations = 0, num_output_observations = 0;
  int64_t num_dropped_observations = 0;
};

struct CalibrationSummary {
  // "1dr", "rd_ra", "rd", "known", "known_refine", "known_ra"
  std::string method;
  // The map's units; a calibration is metric only if the map is.
  std::string units = "map units";
  std::optional<bool> map_looks_metric;  // unknown when not assessed
  std::string reference_camera;
  int num_framesets = 0;
  int num_framesets_used = 0;  // with a rig pose
  std::vector<CameraSummary> cameras;
  std::vector<std::string> diagnostics;  // warnings and notes, in order
  std::vector<std::pair<std::string, double>> timings_s;  // stage, seconds
  std::optional<MapImagesSummary> map_images;             // with a map
};

// The per-camera part and the frameset counts of a calibration; the caller
// sets method, units, map_looks_metric, diagnostics and timings. Camera names
// come from the dataset, image prefixes from `image_prefixes` (one per camera,
// or empty for name + "/"). cam_from_rig is relative to the reference camera.
// Requires ValidateCalibration (src/calibration/rig_dataset.h).
CalibrationSummary SummarizeCalibration(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes);

bool WriteCalibrationSummaryJson(const std::string& path,
                                 const CalibrationSummary& summary,
                                 std::string* error);

}  // namespace rig_calibrator
