// `rig_calibrator [calibrate]`: from a COLMAP database + map (or a 2D-3D
// correspondence file) to a calibrated rig in COLMAP's and Kalibr's formats.
#include <colmap/base/camera_models.h>
#include <colmap/util/timer.h>

#include <algorithm>
#include <boost/algorithm/string.hpp>
#include <boost/filesystem.hpp>
#include <boost/program_options.hpp>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "colmap_ext/io/calibration_summary.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/map_localizer.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/io/model_writer.h"
#include "colmap_ext/io/rig_layout.h"
#include "colmap_ext/io/rig_reference_io.h"
#include "src/calibration/camera_upgrader.h"
#include "src/calibration/pipeline.h"

namespace rig_calibrator {
namespace {

namespace fs = boost::filesystem;
namespace po = boost::program_options;

struct CalibrateOptions {
  std::string database_path;
  std::string image_path;
  std::string input_path;
  std::string output_path;
  std::string correspondences_path;
  std::string output_type = "BIN";
  bool overwrite = false;

  std::string method = "1dr";
  std::string camera_model = "OPENCV";
  std::string reference_camera;
  std::string camera_prefixes;
  double timestamp_tolerance = 0;
  std::string intrinsics_path;
  // On: a map built by COLMAP is less accurate than what the rig's own many
  // observations determine (rendered ring5: rotation 0.055 -> 0.006 deg,
  // projection difference 0.7 -> 0.08 px); the result stays anchored to the
  // map by a similarity.
  bool refine_points = true;
  double radial_max_error_px = 8.0;
  double max_reprojection_error_px = 10.0;
  double loss_scale_px = 1.0;
  int min_num_inliers = 15;
  int num_threads = -1;
  int seed = 0;

  std::string localization_mode = "direct";
  std::string vocab_tree_path;
  int num_retrieved_images = 10;
  int num_checks = PointDescriptorIndex::Options().num_checks;
  int max_descriptors_per_point =
      MapLocalizerOptions().max_descriptors_per_point;
  bool use_database_matches = true;
  colmap::SiftMatchingOptions sift_matching;
};

po::options_description Describe(CalibrateOptions* o) {
  po::options_description description("rig_calibrator [calibrate] options");
  description.add_options()("help,h", "show this help")(
      "database_path", po::value(&o->database_path),
      "COLMAP 3.8 database with the map images and the rig images' features "
      "(never modified)")("image_path", po::value(&o->image_path),
                          "folder of the rig images, one sub-folder per camera "
                          "(cam0/, cam1/, ...)")(
      "input_path", po::value(&o->input_path),
      "the map: a COLMAP sparse model folder (binary or text)")(
      "output_path", po::value(&o->output_path),
      "output folder (written completely or not at all)")(
      "correspondences_path", po::value(&o->correspondences_path),
      "calibrate from this 2D-3D correspondence file instead of matching "
      "against the database (--input_path is then optional)")(
      "output_type", po::value(&o->output_type)->default_value(o->output_type),
      "BIN or TXT, for the COLMAP model and rigs/frames files")(
      "overwrite", po::value(&o->overwrite)->default_value(o->overwrite),
      "replace a non-empty output folder")(
      "RigCalibrator.method", po::value(&o->method)->default_value(o->method),
      "1dr (default, Inf+1DR+RA), rd_ra, rd, known, known_refine")(
      "RigCalibrator.camera_model",
      po::value(&o->camera_model)->default_value(o->camera_model),
      "COLMAP camera model of every camera (e.g. OPENCV, OPENCV_FISHEYE, "
      "FULL_OPENCV, RADIAL), or per camera: cam0:OPENCV,cam1:OPENCV_FISHEYE")(
      "RigCalibrator.reference_camera", po::value(&o->reference_camera),
      "the camera whose frame is the rig frame (default: the first)")(
      "RigCalibrator.camera_prefixes", po::value(&o->camera_prefixes),
      "comma-separated image name prefixes of the cameras (default: the "
      "first-level folders)")(
      "RigCalibrator.timestamp_tolerance",
      po::value(&o->timestamp_tolerance)->default_value(o->timestamp_tolerance),
      "0: a frameset is the images with the same file name; > 0: numeric "
      "names (e.g. nanosecond timestamps) within this tolerance")(
      "RigCalibrator.intrinsics_path", po::value(&o->intrinsics_path),
      "known intrinsics for the known* methods (rig_config.json with "
      "camera_params, or camchain.yaml); default: the database's cameras")(
      "RigCalibrator.refine_points",
      po::value(&o->refine_points)->default_value(o->refine_points),
      "also refine the map points that rig images observe at least twice in "
      "the final bundle adjustment (the result is then aligned back to the "
      "map by a similarity); 0: keep the map points fixed")(
      "RigCalibrator.radial_max_error",
      po::value(&o->radial_max_error_px)->default_value(o->radial_max_error_px),
      "inlier threshold of the 1D radial stages (pixels)")(
      "RigCalibrator.max_reprojection_error",
      po::value(&o->max_reprojection_error_px)
          ->default_value(o->max_reprojection_error_px),
      "inlier threshold of the camera upgrade (pixels)")(
      "RigCalibrator.loss_scale",
      po::value(&o->loss_scale_px)->default_value(o->loss_scale_px),
      "Cauchy loss scale of the bundle adjustments (pixels)")(
      "RigCalibrator.min_num_inliers",
      po::value(&o->min_num_inliers)->default_value(o->min_num_inliers),
      "images with fewer 2D-3D inliers are not localized")(
      "RigCalibrator.num_threads",
      po::value(&o->num_threads)->default_value(o->num_threads),
      "-1: all cores")("RigCalibrator.seed",
                       po::value(&o->seed)->default_value(o->seed),
                       "random seed (results are deterministic for a seed)")(
      "Localization.mode",
      po::value(&o->localization_mode)->default_value(o->localization_mode),
      "direct: match features to an index of the map points' descriptors; "
      "retrieval: match to retrieved map images")(
      "Localization.vocab_tree_path", po::value(&o->vocab_tree_path),
      "COLMAP 3.8 vocabulary tree for retrieval mode (optional)")(
      "Localization.num_retrieved_images",
      po::value(&o->num_retrieved_images)
          ->default_value(o->num_retrieved_images),
      "map images matched per rig image in retrieval mode")(
      "Localization.num_checks",
      po::value(&o->num_checks)->default_value(o->num_checks),
      "direct mode: FLANN leaf checks per rig feature (fewer: faster, "
      "fewer matches; COLMAP's matcher uses 128, twice the time)")(
      "Localization.max_descriptors_per_point",
      po::value(&o->max_descriptors_per_point)
          ->default_value(o->max_descriptors_per_point),
      "direct mode: descriptors indexed per map point")(
      "Localization.use_database_matches",
      po::value(&o->use_database_matches)
          ->default_value(o->use_database_matches),
      "use matches a COLMAP matcher already stored between rig and map "
      "images")("SiftMatching.max_ratio",
                po::value(&o->sift_matching.max_ratio)
                    ->default_value(o->sift_matching.max_ratio),
                "Lowe's ratio test")(
      "SiftMatching.max_distance",
      po::value(&o->sift_matching.max_distance)
          ->default_value(o->sift_matching.max_distance),
      "largest descriptor distance (radians)")(
      "SiftMatching.cross_check",
      po::value(&o->sift_matching.cross_check)
          ->default_value(o->sift_matching.cross_check),
      "retrieval mode: keep mutual best matches only");
  return description;
}

bool Fail(const std::string& message) {
  std::cerr << "ERROR: " << message << std::endl;
  return false;
}

bool IsImageFile(const fs::path& path) {
  std::string extension = path.extension().string();
  boost::algorithm::to_lower(extension);
  static const std::vector<std::string> kExtensions = {
      ".png", ".jpg", ".jpeg", ".pgm", ".ppm", ".bmp", ".tif", ".tiff"};
  return std::find(kExtensions.begin(), kExtensions.end(), extension) !=
         kExtensions.end();
}

// Image names relative to `image_path`, with '/', sorted.
bool ListImages(const std::string& image_path, std::vector<std::string>* names,
                std::string* error) {
  boost::system::error_code fs_error;
  if (!fs::is_directory(image_path, fs_error)) {
    *error =
        "--image_path " + image_path + " does not exist or is not a folder";
    return false;
  }
  const fs::path root = fs::canonical(image_path, fs_error);
  fs::recursive_directory_iterator it(root, fs_error), end;
  for (; !fs_error && it != end; it.increment(fs_error)) {
    boost::system::error_code ignored;
    if (!fs::is_regular_file(it->path(), ignored) || !IsImageFile(it->path())) {
      continue;
    }
    // Lexically: fs::relative would resolve a symlinked image to its target,
    // whereas COLMAP names it by its path under the image folder.
    names->push_back(it->path().lexically_relative(root).generic_string());
  }
  if (fs_error) {
    *error = "cannot list the images under --image_path " + image_path + ": " +
             fs_error.message();
    return false;
  }
  std::sort(names->begin(), names->end());
  if (names->empty()) {
    *error = "no images (png, jpg, pgm, ppm, bmp, tif) under --image_path " +
             image_path;
    return false;
  }
  return true;
}

// "OPENCV" for every camera, or "cam0:OPENCV,cam1:OPENCV_FISHEYE".
bool CameraModels(const std::string& value,
                  const std::vector<std::string>& camera_names,
                  std::vector<std::string>* models, std::string* error) {
  models->assign(camera_names.size(), "");
  std::vector<std::string> items;
  boost::split(items, value, boost::is_any_of(","));
  for (std::string item : items) {
    boost::trim(item);
    if (item.empty()) continue;
    const size_t colon = item.find(':');
    if (colon == std::string::npos) {
      for (std::string& model : *models) {
        if (model.empty()) model = item;
      }
      continue;
    }
    const std::string camera = item.substr(0, colon);
    const auto it = std::find(camera_names.begin(), camera_names.end(), camera);
    if (it == camera_names.end()) {
      *error = "--RigCalibrator.camera_model names camera '" + camera +
               "', which is not a camera of the rig";
      return false;
    }
    (*models)[it - camera_names.begin()] = item.substr(colon + 1);
  }
  for (size_t c = 0; c < models->size(); ++c) {
    const std::string& model = (*models)[c];
    if (model.empty()) {
      *error = "--RigCalibrator.camera_model gives no model for camera " +
               camera_names[c];
      return false;
    }
    if (!colmap::ExistsCameraModelWithName(model) ||
        !IsUpgradeSupportedCameraModel(colmap::CameraModelNameToId(model))) {
      *error = "unknown or unsupported camera model '" + model +
               "' for camera " + camera_names[c] +
               "; supported: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, "
               "OPENCV, OPENCV_FISHEYE, FULL_OPENCV, SIMPLE_RADIAL_FISHEYE, "
               "RADIAL_FISHEYE";
      return false;
    }
  }
  return true;
}

// Builds the dataset's cameras, framesets and images (without
// correspondences) from the rig layout of `image_names`, which come from
// `source` (named in the messages).
bool MakeDataset(const CalibrateOptions& options, const std::string& source,
                 const std::vector<std::string>& image_names,
                 const std::vector<std::pair<int, int>>& image_sizes,
                 RigDataset* dataset, RigLayout* layout, std::string* error) {
  RigLayoutOptions layout_options;
  layout_options.timestamp_tolerance = options.timestamp_tolerance;
  if (!options.camera_prefixes.empty()) {
    boost::split(layout_options.camera_prefixes, options.camera_prefixes,
                 boost::is_any_of(","));
  }
  if (!DiscoverRigLayout(image_names, layout_options, layout, error)) {
    *error = source + ": " + *error;
    return false;
  }
  std::cout << RigLayoutTable(image_names, *layout) << std::endl;

  std::vector<std::string> models;
  if (!CameraModels(options.camera_model, layout->camera_names, &models,
                    error)) {
    return false;
  }
  const int num_cameras = static_cast<int>(layout->camera_names.size());
  std::vector<std::pair<int, int>> camera_sizes(num_cameras, {0, 0});
  for (size_t i = 0; i < image_names.size(); ++i) {
    const int c = layout->images[i].camera_index;
    if (c < 0) continue;
    if (camera_sizes[c].first == 0) {
      camera_sizes[c] = image_sizes[i];
    } else if (camera_sizes[c] != image_sizes[i]) {
      *error = "the images of camera " + layout->camera_names[c] +
               " have different sizes (" + image_names[i] + " is " +
               std::to_string(image_sizes[i].first) + "x" +
               std::to_string(image_sizes[i].second) +
               "): one folder must hold the images of one camera";
      return false;
    }
  }
  for (int c = 0; c < num_cameras; ++c) {
    RigCamera camera;
    camera.name = layout->camera_names[c];
    const auto [width, height] = camera_sizes[c];
    // COLMAP's default initialization: focal 1.2 max(w, h), principal point
    // at the image center. Only the principal point is used before the
    // upgrade estimates the rest.
    camera.camera.InitializeWithName(models[c], 1.2 * std::max(width, height),
                                     width, height);
    dataset->cameras.push_back(camera);
  }
  dataset->frameset_names = layout->frameset_names;
  dataset->reference_camera = 0;
  if (!options.reference_camera.empty()) {
    const auto it =
        std::find(layout->camera_names.begin(), layout->camera_names.end(),
                  options.reference_camera);
    if (it == layout->camera_names.end()) {
      *error = "--RigCalibrator.reference_camera " + options.reference_camera +
               " is not a camera of the rig";
      return false;
    }
    dataset->reference_camera =
        static_cast<int>(it - layout->camera_names.begin());
  }
  for (size_t i = 0; i < image_names.size(); ++i) {
    if (layout->images[i].camera_index < 0) continue;
    RigImage image;
    image.name = image_names[i];
    image.camera_index = layout->images[i].camera_index;
    image.frameset_index = layout->images[i].frameset_index;
    dataset->images.push_back(image);
  }
  return true;
}

// The known* methods: intrinsics from --RigCalibrator.intrinsics_path, else
// from the database cameras of the rig images (as set by
// feature_extractor --ImageReader.camera_params).
bool SetKnownIntrinsics(const CalibrateOptions& options,
                        const std::vector<colmap::Camera>& database_cameras,
                        RigDataset* dataset, std::string* error) {
  std::vector<std::optional<colmap::Camera>> known(dataset->cameras.size());
  if (!options.intrinsics_path.empty()) {
    RigDescription rig;
    if (!ReadRigReference(options.intrinsics_path, &rig, error)) return false;
    for (size_t c = 0; c < dataset->cameras.size(); ++c) {
      for (const RigDescriptionCamera& camera : rig.cameras) {
        if (camera.name == dataset->cameras[c].name && camera.camera) {
          known[c] = *camera.camera;
        }
      }
    }
  } else {
    for (size_t c = 0; c < dataset->cameras.size(); ++c) {
      if (c < database_cameras.size() &&
          database_cameras[c].HasPriorFocalLength()) {
        known[c] = database_cameras[c];
      }
    }
  }
  for (size_t c = 0; c < dataset->cameras.size(); ++c) {
    RigCamera& camera = dataset->cameras[c];
    if (!known[c]) {
      *error = "method " + options.method + " needs the intrinsics of camera " +
               camera.name +
               ": give --RigCalibrator.intrinsics_path, or extract its "
               "features with --ImageReader.camera_model and "
               "--ImageReader.camera_params";
      return false;
    }
    colmap::Camera intrinsics = *known[c];
    if (intrinsics.Width() == 0) {
      intrinsics.SetWidth(camera.camera.Width());
      intrinsics.SetHeight(camera.camera.Height());
    }
    camera.camera = intrinsics;
    camera.intrinsics_known = true;
  }
  return true;
}

bool LoadFromDatabase(const CalibrateOptions& options,
                      const colmap::Reconstruction& map, RigDataset* dataset,
                      RigLayout* layout, std::string* error) {
  std::vector<std::string> image_names;
  if (!ListImages(options.image_path, &image_names, error)) return false;
  DatabaseReader database;
  if (!database.Open(options.database_path, error)) return false;

  std::vector<std::string> missing;
  std::vector<std::pair<int, int>> image_sizes;
  std::map<std::string, colmap::Camera> cameras_by_name;
  for (const std::string& name : image_names) {
    const DatabaseImage* image = database.FindImageWithName(name);
    if (image == nullptr) {
      missing.push_back(name);
      image_sizes.emplace_back(0, 0);
      continue;
    }
    colmap::Camera camera;
    if (!database.ReadCamera(image->camera_id, &camera, error)) return false;
    image_sizes.emplace_back(static_cast<int>(camera.Width()),
                             static_cast<int>(camera.Height()));
    cameras_by_name[name] = camera;
  }
  if (!missing.empty()) {
    *error = std::to_string(missing.size()) + " of the " +
             std::to_string(image_names.size()) + " images under " +
             options.image_path + " are not in the database " +
             options.database_path + " (e.g. " + missing.front() +
             "): run colmap feature_extractor on the rig images into a copy "
             "of the map's database first (scripts/calibrate_rig.sh does)";
    return false;
  }
  for (const colmap::image_t image_id : map.RegImageIds()) {
    const std::string& name = map.Image(image_id).Name();
    if (std::binary_search(image_names.begin(), image_names.end(), name)) {
      *error =
          "image " + name +
          " is both a rig image and a registered map image: keep the rig "
          "images out of the map, or give --image_path the rig images only";
      return false;
    }
  }
  if (!MakeDataset(options,
                   "the rig images under --image_path " + options.image_path,
                   image_names, image_sizes, dataset, layout, error)) {
    return false;
  }
  if (options.method == "known" || options.method == "known_refine") {
    std::vector<colmap::Camera> database_cameras(dataset->cameras.size());
    for (const RigImage& image : dataset->images) {
      database_cameras[image.camera_index] = cameras_by_name[image.name];
    }
    if (!SetKnownIntrinsics(options, database_cameras, dataset, error)) {
      return false;
    }
  }

  MapLocalizerOptions localizer_options;
  if (!LocalizationModeFromName(options.localization_mode,
                                &localizer_options.mode)) {
    *error = "--Localization.mode must be direct or retrieval, not " +
             options.localization_mode;
    return false;
  }
  localizer_options.sift_matching.max_ratio = options.sift_matching.max_ratio;
  localizer_options.sift_matching.max_distance =
      options.sift_matching.max_distance;
  localizer_options.sift_matching.cross_check =
      options.sift_matching.cross_check;
  localizer_options.vocab_tree_path = options.vocab_tree_path;
  localizer_options.num_retrieved_images = options.num_retrieved_images;
  localizer_options.index.num_checks = options.num_checks;
  localizer_options.max_descriptors_per_point =
      options.max_descriptors_per_point;
  localizer_options.use_database_matches = options.use_database_matches;
  localizer_options.num_threads = options.num_threads;
  if (!localizer_options.Check(error)) return false;

  std::cout << "== Localization against the map (" << options.localization_mode
            << ")" << std::endl;
  colmap::Timer timer;
  timer.Start();
  const std::unique_ptr<MapLocalizer> localizer =
      MapLocalizer::Create(localizer_options, map, &database, error);
  if (localizer == nullptr) return false;
  std::vector<std::string> names;
  for (const RigImage& image : dataset->images) names.push_back(image.name);
  std::vector<ImageLocalization> localizations;
  if (!localizer->LocalizeImages(names, &localizations, error)) return false;
  size_t num_correspondences = 0;
  for (size_t i = 0; i < dataset->images.size(); ++i) {
    dataset->images[i].correspondences =
        std::move(localizations[i].correspondences);
    num_correspondences += dataset->images[i].correspondences.size();
  }
  std::cout << "  " << num_correspondences << " 2D-3D correspondences for "
            << dataset->images.size() << " images against "
            << localizer->NumMapImages() << " map images and "
            << localizer->NumMapPoints() << " map points in " << std::fixed
            << std::setprecision(1) << timer.ElapsedSeconds() << " s"
            << std::endl;
  return true;
}

bool LoadFromCorrespondences(const CalibrateOptions& options,
                             RigDataset* dataset, RigLayout* layout,
                             std::string* error) {
  std::vector<ImageCorrespondences> images;
  if (!ReadCorrespondenceFile(options.correspondences_path, &images, error)) {
    return false;
  }
  std::vector<std::string> image_names;
  std::vector<std::pair<int, int>> image_sizes;
  std::map<std::string, size_t> index_by_name;
  for (size_t i = 0; i < images.size(); ++i) {
    image_names.push_back(images[i].image_name);
    image_sizes.emplace_back(images[i].width, images[i].height);
    index_by_name[images[i].image_name] = i;
  }
  if (!MakeDataset(options,
                   "the images of --correspondences_path " +
                       options.correspondences_path,
                   image_names, image_sizes, dataset, layout, error)) {
    return false;
  }
  if (options.method == "known" || options.method == "known_refine") {
    if (!SetKnownIntrinsics(options, {}, dataset, error)) return false;
  }
  for (RigImage& image : dataset->images) {
    image.correspondences =
        std::move(images[index_by_name[image.name]].correspondences);
  }
  return true;
}

void PrintResult(const RigDataset& dataset, const RigCalibration& calibration,
                 const PipelineReport& report,
                 const CalibrationSummary& summary) {
  std::cout << "\n== Result (" << CalibrationMethodName(report.used_method)
            << ", " << report.num_used << " of " << report.num_images
            << " images used, " << report.num_framesets_posed << " of "
            << dataset.frameset_names.size() << " framesets, RMS "
            << std::setprecision(3) << report.final_rms_px << " px, "
            << std::fixed << std::setprecision(1) << report.total_seconds
            << " s)\n"
            << std::defaultfloat;
  for (const CameraSummary& camera : summary.cameras) {
    std::cout << "  " << std::left << std::setw(8) << camera.name << std::right;
    if (!camera.calibrated) {
      std::cout << " not calibrated\n";
      continue;
    }
    const Eigen::Vector3d center = camera.cam_from_rig->Center();
    std::cout << " " << camera.camera.ModelName() << " f "
              << std::setprecision(2) << std::fixed
              << camera.camera.MeanFocalLength() << " pp ("
              << camera.camera.PrincipalPointX() << ", "
              << camera.camera.PrincipalPointY() << ") center in rig ("
              << std::setprecision(4) << center.x() << ", " << center.y()
              << ", " << center.z() << ") images " << camera.num_used << "/"
              << camera.num_images << " RMS " << std::setprecision(3)
              << camera.rms_px << " px\n";
  }
  for (const Diagnostic& diagnostic : report.diagnostics) {
    std::cout << "  " << DiagnosticLevelName(diagnostic.level) << ": "
              << diagnostic.message << "\n";
  }
  std::cout << std::flush;
}

}  // namespace

int RunCalibrate(int argc, char** argv) {
  CalibrateOptions options;
  const po::options_description description = Describe(&options);
  int exit_code = EXIT_SUCCESS;
  if (!ParseCommandLine(argc, argv, description,
                        "rig_calibrator [calibrate]: calibrate a multi-camera "
                        "rig against a COLMAP map",
                        &exit_code)) {
    return exit_code;
  }

  std::string error;
  const bool from_correspondences = !options.correspondences_path.empty();
  if (options.output_path.empty()) {
    Fail("--output_path is required");
    return EXIT_FAILURE;
  }
  if (!from_correspondences &&
      (options.database_path.empty() || options.image_path.empty() ||
       options.input_path.empty())) {
    Fail(
        "give --database_path, --image_path and --input_path (the map), or "
        "--correspondences_path");
    return EXIT_FAILURE;
  }
  boost::to_upper(options.output_type);
  if (options.output_type != "BIN" && options.output_type != "TXT") {
    Fail("--output_type must be BIN or TXT, not " + options.output_type);
    return EXIT_FAILURE;
  }
  PipelineOptions pipeline;
  if (!CalibrationMethodFromName(options.method, &pipeline.method)) {
    Fail(
        "--RigCalibrator.method must be one of 1dr, rd_ra, rd, known, "
        "known_refine, not " +
        options.method);
    return EXIT_FAILURE;
  }

  colmap::Reconstruction map;
  if (!options.input_path.empty()) {
    std::cout << "== Reading the map " << options.input_path << std::endl;
    if (!ReadMap(options.input_path, &map, &error)) {
      Fail(error);
      return EXIT_FAILURE;
    }
    std::cout << "  " << map.NumRegImages() << " images, " << map.NumPoints3D()
              << " points" << std::endl;
  }

  RigDataset dataset;
  RigLayout layout;
  const bool loaded =
      from_correspondences
          ? LoadFromCorrespondences(options, &dataset, &layout, &error)
          : LoadFromDatabase(options, map, &dataset, &layout, &error);
  if (!loaded) {
    Fail(error);
    return EXIT_FAILURE;
  }

  pipeline.num_threads = options.num_threads;
  pipeline.seed = static_cast<unsigned int>(options.seed);
  pipeline.initial_pose.radial.max_error_px = options.radial_max_error_px;
  pipeline.initial_pose.min_num_inliers = options.min_num_inliers;
  pipeline.rig_initializer.max_radial_error_px = options.radial_max_error_px;
  pipeline.upgrade_radial_max_error_px = options.radial_max_error_px;
  pipeline.upgrade.max_error_px = options.max_reprojection_error_px;
  pipeline.initial_pose.upgrade.max_error_px =
      options.max_reprojection_error_px;
  pipeline.radial_bundle_adjustment.loss_scale_px = options.loss_scale_px;
  pipeline.final_bundle_adjustment.loss_scale_px = options.loss_scale_px;
  pipeline.final_bundle_adjustment.refine_points = options.refine_points;

  RigCalibration calibration;
  PipelineReport report;
  if (!CalibrateRig(pipeline, dataset, &calibration, &report)) {
    for (const Diagnostic& diagnostic : report.diagnostics) {
      std::cerr << DiagnosticLevelName(diagnostic.level) << ": "
                << diagnostic.message << std::endl;
    }
    Fail("calibration failed: " + report.error);
    return EXIT_FAILURE;
  }

  CalibrationSummary summary =
      SummarizeCalibration(dataset, calibration, layout.camera_prefixes);
  summary.method = CalibrationMethodName(report.used_method);
  for (const Diagnostic& diagnostic : report.diagnostics) {
    summary.diagnostics.push_back(DiagnosticLevelName(diagnostic.level) + " " +
                                  diagnostic.code + ": " + diagnostic.message);
  }
  for (const StageTiming& timing : report.timings) {
    summary.timings_s.emplace_back(timing.stage, timing.seconds);
  }

  RigOutputOptions output_options;
  output_options.output_type = options.output_type;
  output_options.overwrite = options.overwrite;
  for (const std::string& input :
       {options.database_path, options.image_path, options.input_path,
        options.correspondences_path}) {
    if (!input.empty()) output_options.input_paths.push_back(input);
  }
  std::vector<std::string> notes;
  if (!WriteRigOutput(options.output_path, map, dataset, calibration,
                      layout.camera_prefixes, summary, output_options, &notes,
                      &error)) {
    Fail("writing the output failed, nothing was written: " + error);
    return EXIT_FAILURE;
  }
  PrintResult(dataset, calibration, report, summary);
  for (const std::string& note : notes) std::cout << "  note: " << note << "\n";
  std::cout << "\nOutputs in " << options.output_path
            << ": COLMAP model (open with `colmap gui --import_path` or "
               "`colmap model_analyzer --path`), rigs/frames and "
               "rig_config.json for COLMAP >= 3.12, "
               "rig_bundle_adjuster_config.json for COLMAP 3.8, camchain.yaml "
               "(Kalibr), calibration_summary.json, correspondences.txt."
            << std::endl;
  if (report.HasErrors()) {
    Fail("some cameras could not be calibrated (see above)");
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
