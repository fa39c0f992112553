// The options of `rig_calibrator [calibrate]` and what they set: the
// pipeline's and the localizer's options.
#pragma once

#include <colmap/feature/sift.h>

#include <boost/program_options.hpp>
#include <string>

#include "colmap_ext/localization/map_localizer.h"
#include "src/calibration/calibration_method.h"
#include "src/calibration/pipeline.h"

namespace rig_calibrator {

struct CalibrateOptions {
  std::string database_path;
  std::string image_path;
  std::string input_path;
  std::string output_path;
  std::string correspondences_path;
  std::string output_type = "BIN";
  bool overwrite = false;

  std::string method = "1dr";
  std::string camera_model = "auto";
  std::string reference_camera;
  std::string camera_prefixes;
  double timestamp_tolerance = 0;
  // Seconds per unit of the numeric names (the frameset times of the
  // capture-time offsets, capture_timing.h).
  double timestamp_unit_s = 1e-9;
  // "auto": remove each camera's constant timestamp offset, estimated from
  // the names, before grouping (timestamp_offsets.h); "0": none.
  std::string timestamp_offsets = "auto";
  std::string intrinsics_path;
  // COLMAP's refinement switches, "1"/"0" or per camera "cam0:0,cam1:1"
  // (intrinsics_refinement_input.h).
  std::string refine_focal_length = "1";
  std::string refine_principal_point = "1";
  std::string refine_extra_params = "1";
  // On: a map built by COLMAP is less accurate than what the rig's own many
  // observations determine (rendered ring5: rotation 0.055 -> 0.006 deg,
  // projection difference 0.7 -> 0.08 px); the result stays anchored to the
  // map by a similarity.
  bool refine_points = true;
  // The map images' observations of the refined points take part in the
  // final bundle adjustment (final_bundle_adjuster.h); refine_map: the map
  // images' poses (refine_map_intrinsics: and the map cameras) are adjusted
  // with the rig. On by default: on the rendered ring5 demo the worst camera
  // goes from 0.0083 deg / 0.36 mm (rig observations only) to 0.0035 deg /
  // 0.17 mm, while holding the map poses fixed makes it 0.051 deg / 2.7 mm
  // (scripts/final_adjustment_variants.sh).
  bool map_observations = true;
  bool refine_map = true;
  bool refine_map_intrinsics = false;
  // A new database (copy of --database_path) with the rig-to-map matches.
  std::string export_database;
  double radial_max_error_px = 8.0;
  double max_reprojection_error_px = 10.0;
  double loss_scale_px = 1.0;
  int min_num_inliers = 15;
  int num_threads = -1;
  int seed = 0;
  // The bundle adjustments' solver backend (bundle_solver.h): own or ceres.
  std::string bundle_solver = "own";
  // The final adjustment's capture-time model (capture_time_model.h):
  // auto, 0 or 1, for the offsets and the rolling shutter's line delays.
  std::string time_offsets = "auto";
  std::string rolling_shutter = "auto";

  std::string localization_mode = "direct";
  std::string vocab_tree_path;
  int num_retrieved_images = 10;
  int num_checks = PointDescriptorIndex::Options().num_checks;
  int max_descriptors_per_point =
      MapLocalizerOptions().max_descriptors_per_point;
  bool use_database_matches = true;
  MapLocalizerOptions::Guidance guidance;
  colmap::SiftMatchingOptions sift_matching;

  bool FromCorrespondences() const { return !correspondences_path.empty(); }
  // The known* methods (known, known_refine, known_ra), which take the
  // intrinsics as given.
  bool KnownIntrinsics() const {
    CalibrationMethod value;
    return CalibrationMethodFromName(method, &value) &&
           UsesKnownIntrinsics(value);
  }
};

// The command-line options, bound to the fields of *options.
boost::program_options::options_description DescribeCalibrateOptions(
    CalibrateOptions* options);

// The Localization.* and SiftMatching.* options alone (also those of
// `rig_calibrator_lab benchmark_localization`).
boost::program_options::options_description DescribeLocalizationOptions(
    CalibrateOptions* options);

// Checks the combination of inputs, upper-cases output_type and sets
// *pipeline from the options; false with the message (naming the option)
// in *error.
bool MakePipelineOptions(CalibrateOptions* options, PipelineOptions* pipeline,
                         std::string* error);

// The localizer's options (Localization.*, SiftMatching.*); false with
// *error for an unknown mode or values out of range.
bool MakeLocalizerOptions(const CalibrateOptions& options,
                          MapLocalizerOptions* localizer_options,
                          std::string* error);

}  // namespace rig_calibrator
