#include "colmap_ext/commands/calibrate_options.h"

#include <boost/algorithm/string.hpp>
#include <boost/filesystem.hpp>

#include "colmap_ext/commands/command_options.h"

namespace rig_calibrator {
namespace {

namespace po = boost::program_options;

void AddInputOutputOptions(po::options_description* description,
                           CalibrateOptions* o) {
  AddUnsetOption(description, "database_path", &o->database_path,
                 "COLMAP database (of COLMAP 3.8 to 4.1) with the map images "
                 "and the rig images' SIFT features (never modified)");
  AddUnsetOption(description, "image_path", &o->image_path,
                 "folder of the rig images, one sub-folder per camera "
                 "(cam0/, cam1/, ...)");
  AddUnsetOption(description, "input_path", &o->input_path,
                 "the map: a COLMAP sparse model folder (binary or text, of "
                 "COLMAP 3.8 to 4.1)");
  AddUnsetOption(description, "output_path", &o->output_path,
                 "output folder (written completely or not at all)");
  AddUnsetOption(description, "correspondences_path", &o->correspondences_path,
                 "calibrate from this 2D-3D correspondence file instead of "
                 "matching against the database (--input_path is then "
                 "optional)");
  AddOption(description, "output_type", &o->output_type,
            "BIN or TXT, for the COLMAP model and rigs/frames files");
  AddOverwriteOption(description, &o->overwrite);
}

void AddRigCalibratorOptions(po::options_description* description,
                             CalibrateOptions* o) {
  AddOption(description, "RigCalibrator.method", &o->method,
            "1dr (default, Inf+1DR+RA), rd_ra (Inf+RD+RA), rd (Inf+RD), "
            "known (Inf+K), known_refine (Inf+K+RI), known_ra (given "
            "intrinsics, robust rig initialization); rd, known and "
            "known_refine need a frameset in which every camera is "
            "localized");
  AddOption(description, "RigCalibrator.camera_model", &o->camera_model,
            "auto (the default: chosen among pinhole-type and fisheye "
            "models by held-out reprojection error), or the COLMAP camera "
            "model of every camera (e.g. OPENCV, OPENCV_FISHEYE, "
            "FULL_OPENCV, RADIAL), or per camera: cam0:OPENCV,cam1:auto");
  AddUnsetOption(description, "RigCalibrator.reference_camera",
                 &o->reference_camera,
                 "the camera whose frame is the rig frame (default: the "
                 "first)");
  AddUnsetOption(description, "RigCalibrator.camera_prefixes",
                 &o->camera_prefixes,
                 "comma-separated image name prefixes of the cameras "
                 "(default: the first-level folders)");
  AddOption(description, "RigCalibrator.timestamp_tolerance",
            &o->timestamp_tolerance,
            "0: a frameset is the images with the same file name; > 0: "
            "numeric names (e.g. nanosecond timestamps) within this "
            "tolerance");
  AddOption(description, "RigCalibrator.timestamp_unit_s",
            &o->timestamp_unit_s,
            "seconds per unit of the numeric names (1e-9: nanoseconds); "
            "with timestamp_tolerance > 0 they give the frameset times of "
            "the capture-time offsets");
  AddOption(description, "RigCalibrator.timestamp_offsets",
            &o->timestamp_offsets,
            "auto: remove each camera's constant timestamp offset against "
            "the reference camera (estimated from the names: the offset "
            "pairing most images within timestamp_tolerance) before "
            "grouping; 0: group the names as they are");
  AddUnsetOption(description, "RigCalibrator.intrinsics_path",
                 &o->intrinsics_path,
                 "known intrinsics for the known* methods (rig_config.json "
                 "with camera_params, or camchain.yaml); default: the "
                 "database's cameras");
  const std::string held =
      " (0: held at its given value in every stage: from "
      "--RigCalibrator.intrinsics_path, else the database camera's "
      "--ImageReader.camera_params; COLMAP's bundle_adjuster meaning); 1 or "
      "0 for every camera, or per camera: cam0:0,cam1:1; the known and "
      "known_ra methods hold every intrinsic";
  AddOption(description, "RigCalibrator.refine_focal_length",
            &o->refine_focal_length,
            "estimate the focal length" + held +
                "; held without a given focal length is an error");
  AddOption(description, "RigCalibrator.refine_principal_point",
            &o->refine_principal_point,
            "estimate the principal point" + held +
                "; held without one given: the image centre");
  AddOption(description, "RigCalibrator.refine_extra_params",
            &o->refine_extra_params,
            "estimate the distortion" + held +
                "; held without one given: 0, no distortion");
  AddOption(description, "RigCalibrator.refine_points", &o->refine_points,
            "also refine the map points that rig images observe at least "
            "twice in the final bundle adjustment (the result is then "
            "aligned back to the map by a similarity); 0: keep the map "
            "points fixed");
  AddOption(description, "RigCalibrator.map_observations", &o->map_observations,
            "with refine_points and a map (--input_path): the map images' "
            "observations of the refined points are residuals too, the map "
            "images' poses and cameras held fixed");
  AddOption(description, "RigCalibrator.refine_map", &o->refine_map,
            "adjust every map image's pose and every map point with the rig "
            "(with refine_points, map_observations and a map; the result is "
            "aligned to the input map's camera centres by a similarity); 0: "
            "the map images' poses stay fixed");
  AddOption(description, "RigCalibrator.refine_map_intrinsics",
            &o->refine_map_intrinsics,
            "with refine_map: also adjust the map cameras' intrinsics");
  AddUnsetOption(description, "RigCalibrator.export_database",
                 &o->export_database,
                 "write a copy of --database_path with the rig images' "
                 "verified matches to the map images (for COLMAP's "
                 "point_triangulator, mapper, bundle_adjuster); a new file");
  AddOption(description, "RigCalibrator.radial_max_error",
            &o->radial_max_error_px,
            "inlier threshold of the 1D radial stages (pixels)");
  AddOption(description, "RigCalibrator.max_reprojection_error",
            &o->max_reprojection_error_px,
            "inlier threshold of the camera upgrade (pixels)");
  AddOption(description, "RigCalibrator.loss_scale", &o->loss_scale_px,
            "Cauchy loss scale of the bundle adjustments (pixels)");
  AddOption(description, "RigCalibrator.min_num_inliers", &o->min_num_inliers,
            "images with fewer 2D-3D inliers are not localized");
  AddOption(description, "RigCalibrator.num_threads", &o->num_threads,
            "-1: all cores (the result does not depend on the count)");
  AddOption(description, "RigCalibrator.seed", &o->seed,
            "random seed (results are deterministic for a seed)");
  AddOption(description, "RigCalibrator.bundle_solver", &o->bundle_solver,
            "solver of the bundle adjustments: own (the project's "
            "Levenberg-Marquardt) or ceres (Ceres', the reference it is "
            "compared with: the same minimum, slower, and not bit-identical "
            "across thread counts)");
  AddOption(description, "RigCalibrator.time_offsets", &o->time_offsets,
            "per-camera capture-time offsets in the final adjustment (needs "
            "frameset times): 1 estimate, 0 not, auto estimate and keep when "
            "significant (> 3 sigma and > 1 ms)");
  AddOption(description, "RigCalibrator.rolling_shutter",
            &o->rolling_shutter,
            "per-camera rolling-shutter line delays in the final adjustment "
            "(needs frameset times): 1, 0 or auto (kept when the readout "
            "time is > 3 sigma and > 1 ms)");
}

void AddLocalizationOptions(po::options_description* description,
                            CalibrateOptions* o) {
  AddOption(description, "Localization.mode", &o->localization_mode,
            "direct: match features to an index of the map points' "
            "descriptors; retrieval: match to retrieved map images");
  AddUnsetOption(description, "Localization.vocab_tree_path",
                 &o->vocab_tree_path,
                 "COLMAP 3.8 vocabulary tree for retrieval mode (optional)");
  AddOption(description, "Localization.num_retrieved_images",
            &o->num_retrieved_images,
            "map images matched per rig image in retrieval mode");
  AddOption(description, "Localization.num_checks", &o->num_checks,
            "direct mode: FLANN leaf checks per rig feature (fewer: faster, "
            "fewer matches; COLMAP's matcher uses 128, twice the time)");
  AddOption(description, "Localization.max_descriptors_per_point",
            &o->max_descriptors_per_point,
            "direct mode: descriptors indexed per map point");
  AddOption(description, "Localization.guided", &o->guidance.enabled,
            "direct mode: search the strongest features first and, once the "
            "image's 1D radial pose is certain, match the rest only to the "
            "map points near their radial lines (0: search every feature)");
  AddOption(description, "Localization.guided_batch_size",
            &o->guidance.batch_size,
            "direct mode: features searched per batch before the pose is "
            "certain");
  AddOption(description, "Localization.guided_min_pose_inliers",
            &o->guidance.min_pose_inliers,
            "direct mode: radial pose inliers that make the pose certain");
  AddOption(description, "Localization.guided_max_line_distance",
            &o->guidance.max_line_distance_px,
            "direct mode: largest distance of a guided match from the "
            "point's radial line (pixels)");
  AddOption(description, "Localization.guided_max_ratio",
            &o->guidance.max_ratio,
            "direct mode: Lowe's ratio test of a guided match, against the "
            "second-nearest point near the same radial line");
  AddOption(description, "Localization.use_database_matches",
            &o->use_database_matches,
            "use matches a COLMAP matcher already stored between rig and map "
            "images");
  AddOption(description, "SiftMatching.max_ratio", &o->sift_matching.max_ratio,
            "Lowe's ratio test");
  AddOption(description, "SiftMatching.max_distance",
            &o->sift_matching.max_distance,
            "largest descriptor distance (radians)");
  AddOption(description, "SiftMatching.cross_check",
            &o->sift_matching.cross_check,
            "retrieval mode: keep mutual best matches only");
}

}  // namespace

po::options_description DescribeLocalizationOptions(CalibrateOptions* options) {
  po::options_description description("localization options");
  AddLocalizationOptions(&description, options);
  return description;
}

po::options_description DescribeCalibrateOptions(CalibrateOptions* options) {
  po::options_description description =
      CommandOptions("rig_calibrator [calibrate] options");
  AddInputOutputOptions(&description, options);
  AddRigCalibratorOptions(&description, options);
  AddLocalizationOptions(&description, options);
  return description;
}

bool MakePipelineOptions(CalibrateOptions* options, PipelineOptions* pipeline,
                         std::string* error) {
  if (options->output_path.empty()) {
    *error = "--output_path is required";
    return false;
  }
  if (!options->FromCorrespondences() &&
      (options->database_path.empty() || options->image_path.empty() ||
       options->input_path.empty())) {
    *error =
        "give --database_path, --image_path and --input_path (the map), or "
        "--correspondences_path";
    return false;
  }
  boost::to_upper(options->output_type);
  if (options->output_type != "BIN" && options->output_type != "TXT") {
    *error = "--output_type must be BIN or TXT, not " + options->output_type;
    return false;
  }
  if (!CalibrationMethodFromName(options->method, &pipeline->method)) {
    *error =
        "--RigCalibrator.method must be one of 1dr, rd_ra, rd, known, "
        "known_refine, known_ra, not " +
        options->method;
    return false;
  }
  BundleSolverBackend bundle_solver;
  if (!BundleSolverBackendFromName(options->bundle_solver, &bundle_solver)) {
    *error = "--RigCalibrator.bundle_solver must be own or ceres, not " +
             options->bundle_solver;
    return false;
  }
  pipeline->radial_bundle_adjustment.bundle_solver = bundle_solver;
  if (!CaptureTimeModeFromName(options->time_offsets,
                               &pipeline->capture_time_model.time_offsets) ||
      !CaptureTimeModeFromName(options->rolling_shutter,
                               &pipeline->capture_time_model.rolling_shutter)) {
    *error =
        "--RigCalibrator.time_offsets and rolling_shutter must be auto, 0 or "
        "1, not " +
        options->time_offsets + " / " + options->rolling_shutter;
    return false;
  }
  pipeline->final_bundle_adjustment.bundle_solver = bundle_solver;
  pipeline->num_threads = options->num_threads;
  pipeline->seed = static_cast<unsigned int>(options->seed);
  pipeline->initial_pose.radial.max_error_px = options->radial_max_error_px;
  pipeline->initial_pose.min_num_inliers = options->min_num_inliers;
  pipeline->rig_initializer.max_radial_error_px = options->radial_max_error_px;
  pipeline->upgrade_radial_max_error_px = options->radial_max_error_px;
  pipeline->upgrade.max_error_px = options->max_reprojection_error_px;
  pipeline->initial_pose.upgrade.max_error_px =
      options->max_reprojection_error_px;
  pipeline->radial_bundle_adjustment.loss_scale_px = options->loss_scale_px;
  pipeline->final_bundle_adjustment.loss_scale_px = options->loss_scale_px;
  pipeline->final_bundle_adjustment.refine_points = options->refine_points;
  pipeline->final_bundle_adjustment.use_map_observations =
      options->map_observations;
  // The map is adjusted with the rig only where there is one to adjust.
  pipeline->final_bundle_adjustment.refine_map =
      options->refine_map && options->refine_points &&
      options->map_observations && !options->input_path.empty();
  pipeline->final_bundle_adjustment.refine_map_intrinsics =
      pipeline->final_bundle_adjustment.refine_map &&
      options->refine_map_intrinsics;
  if (options->refine_map_intrinsics && !options->refine_map) {
    *error =
        "--RigCalibrator.refine_map_intrinsics 1 needs "
        "--RigCalibrator.refine_map 1";
    return false;
  }
  if (!options->export_database.empty() &&
      (options->database_path.empty() || options->input_path.empty())) {
    *error =
        "--RigCalibrator.export_database needs the map's database "
        "(--database_path) and model (--input_path)";
    return false;
  }
  if (!options->export_database.empty()) {
    // Checked before the calibration, so that a bad path costs no run.
    boost::system::error_code code;
    if (boost::filesystem::exists(options->export_database, code)) {
      *error = "--RigCalibrator.export_database " + options->export_database +
               " exists; give the path of a new file (it never overwrites)";
      return false;
    }
  }
  return true;
}

bool MakeLocalizerOptions(const CalibrateOptions& options,
                          MapLocalizerOptions* localizer_options,
                          std::string* error) {
  if (!LocalizationModeFromName(options.localization_mode,
                                &localizer_options->mode)) {
    *error = "--Localization.mode must be direct or retrieval, not " +
             options.localization_mode;
    return false;
  }
  localizer_options->sift_matching.max_ratio = options.sift_matching.max_ratio;
  localizer_options->sift_matching.max_distance =
      options.sift_matching.max_distance;
  localizer_options->sift_matching.cross_check =
      options.sift_matching.cross_check;
  localizer_options->vocab_tree_path = options.vocab_tree_path;
  localizer_options->num_retrieved_images = options.num_retrieved_images;
  localizer_options->index.num_checks = options.num_checks;
  localizer_options->index.seed = static_cast<unsigned int>(options.seed);
  localizer_options->max_descriptors_per_point =
      options.max_descriptors_per_point;
  localizer_options->use_database_matches = options.use_database_matches;
  localizer_options->guidance = options.guidance;
  localizer_options->num_threads = options.num_threads;
  return localizer_options->Check(error);
}

}  // namespace rig_calibrator
