// The machine-readable summary of a calibration (calibration_summary.json):
// per camera the model, parameters, cam_from_rig and how well the images
// support them; globally the method, the seed, the units and diagnostics.
// The stage timings, the only part that changes from run to run, go to a
// file of their own (timings.json), so that two runs of the same input give
// identical summaries.
#pragma once

#include <colmap/base/camera.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "src/calibration/calibration_uncertainty.h"
#include "src/calibration/camera_model_report.h"
#include "src/calibration/camera_timing.h"
#include "src/calibration/capture_time_model.h"
#include "src/calibration/capture_timing.h"
#include "src/calibration/image_coverage.h"
#include "src/calibration/stage_timing.h"
#include "src/geometry/rigid3d.h"
#include "src/rig/intrinsics_refinement.h"
#include "src/rig/rig_dataset.h"

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
  // Validity of the model and its automatic choice (model_validity_json.h).
  CameraModelReport camera_model;
  // The coverage of the image by the inliers and what of the intrinsics was
  // estimated (PipelineReport::coverage, refined_intrinsics; coverage_json.h).
  std::optional<ImageCoverage> coverage;
  std::optional<IntrinsicsRefinement> refined;
  // The capture timing (camera_timing.h), when some step produced one;
  // written as the camera's "timing" only then.
  std::optional<CameraTiming> timing;
};

// Known cam_from_rig of the rig cameras, e.g. the sensor_from_rig of a
// COLMAP >= 3.12 database's rig_sensors (set by rig_configurator), to compare
// the calibration with.
struct KnownRigPrior {
  std::string source;  // e.g. "database calib.db, rig 2"
  // The dataset index of the known rig's reference camera; -1: no prior.
  int reference_camera = -1;
  // Per dataset camera, cam_from_ref (the identity for the reference camera;
  // unknown where not given).
  std::vector<std::optional<Rigid3d>> cam_from_ref;
};

// The calibrated cam_from_ref of one camera against its KnownRigPrior.
struct KnownPoseComparison {
  std::string camera;
  double rotation_error_deg = 0;
  // |t_calibrated - t_known| in the map's units (the known translation is in
  // the units rig_configurator was given, meters for a metric map).
  double translation_error = 0;
  double known_translation_norm = 0;
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
  unsigned int seed = 0;  // --RigCalibrator.seed
  // The map's units; a calibration is metric only if the map is.
  std::string units = "map units";
  std::optional<bool> map_looks_metric;  // unknown when not assessed
  std::string reference_camera;
  int num_framesets = 0;
  int num_framesets_used = 0;  // with a rig pose
  std::vector<CameraSummary> cameras;
  // The comparison with a known rig (empty source: none), per camera with
  // both a known and a calibrated pose, the reference camera excluded.
  std::string known_rig_source;
  std::string known_rig_reference_camera;
  std::vector<KnownPoseComparison> known_rig_comparison;
  std::vector<std::string> diagnostics;  // warnings and notes, in order
  // Per stage: wall and CPU seconds, solver iterations; written by
  // WriteTimingsJson only.
  std::vector<StageTiming> timings;
  std::optional<MapImagesSummary> map_images;  // with a map
  CalibrationUncertainty uncertainty;          // of the pipeline's report
  // The capture-time offsets (PipelineReport::capture_timing); written as
  // "capture_time_offsets" only when computed.
  CaptureTiming capture_timing;
  // Per camera the constant removed from its numeric names before they were
  // grouped into framesets (rig_layout.h, timestamp_offsets.h), in seconds;
  // empty when the framesets did not come from timestamps. Written as
  // "timestamp_offsets" only when one is not 0, so that names without
  // offsets give the summary they gave before.
  std::vector<double> timestamp_offsets_s;
  // The final adjustment's time model (PipelineReport::capture_time_model);
  // written as "capture_time_model" only when computed.
  CaptureTimeModel capture_time_model;
};

// The per-camera part and the frameset counts of a calibration; the caller
// sets method, seed, units, map_looks_metric, diagnostics and timings. Camera
// names come from the dataset, image prefixes from `image_prefixes` (one per
// camera, or empty for name + "/"). cam_from_rig is relative to the reference
// camera. Requires ValidateCalibration (src/rig/rig_dataset.h).
CalibrationSummary SummarizeCalibration(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes);

// The calibration's cam_from_ref against `prior` (the reference: the
// prior's): fills the known_rig_* fields. No-op without a prior.
void CompareWithKnownRig(const KnownRigPrior& prior,
                         CalibrationSummary* summary);

// Everything but the timings.
bool WriteCalibrationSummaryJson(const std::string& path,
                                 const CalibrationSummary& summary,
                                 std::string* error);

// {"timings_s": {stage: wall seconds, ...}, "cpu_s": {stage: CPU seconds of
// all threads, ...}, "iterations": {stage: solver iterations, ...}} (the
// last for the stages with a bundle adjustment).
bool WriteTimingsJson(const std::string& path,
                      const CalibrationSummary& summary, std::string* error);

}  // namespace rig_calibrator
