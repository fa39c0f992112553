#include "colmap_ext/commands/calibration_input.h"

#include <colmap/base/camera_models.h>
#include <colmap/util/timer.h>

#include <algorithm>
#include <boost/algorithm/string.hpp>
#include <boost/filesystem.hpp>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>

#include "colmap_ext/commands/intrinsics_refinement_input.h"
#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/io/rig_reference_io.h"
#include "colmap_ext/localization/map_localizer.h"
#include "src/calibration/camera_upgrader.h"
#include "src/calibration/model_selection.h"

namespace rig_calibrator {
namespace {

namespace fs = boost::filesystem;

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

// "OPENCV" for every camera, or "cam0:OPENCV,cam1:OPENCV_FISHEYE"; "auto"
// (kAutoCameraModel) where the pipeline chooses the model.
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
    if (model == kAutoCameraModel) continue;
    if (!colmap::ExistsCameraModelWithName(model) ||
        !IsUpgradeSupportedCameraModel(colmap::CameraModelNameToId(model))) {
      *error = "unknown or unsupported camera model '" + model +
               "' for camera " + camera_names[c] +
               "; supported: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, "
               "OPENCV, OPENCV_FISHEYE, FULL_OPENCV, SIMPLE_RADIAL_FISHEYE, "
               "RADIAL_FISHEYE, THIN_PRISM_FISHEYE, or auto";
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
                 RigDataset* dataset, RigLayout* layout, std::string* error,
                 const RigLayoutOptions& frames = RigLayoutOptions()) {
  RigLayoutOptions layout_options = frames;
  layout_options.timestamp_tolerance = options.timestamp_tolerance;
  layout_options.reference_camera = options.reference_camera;
  if (options.timestamp_offsets != "auto" && options.timestamp_offsets != "0") {
    *error = "--RigCalibrator.timestamp_offsets must be auto or 0, not '" +
             options.timestamp_offsets + "'";
    return false;
  }
  layout_options.estimate_timestamp_offsets =
      options.timestamp_offsets == "auto";
  if (!(options.timestamp_unit_s > 0) ||
      !std::isfinite(options.timestamp_unit_s)) {
    *error = "--RigCalibrator.timestamp_unit_s must be a finite number > 0";
    return false;
  }
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
    // An automatically chosen model starts as OPENCV: the radial stages use
    // only its principal point, the full-pose methods' single-image fits
    // its model until the choice.
    camera.choose_model = models[c] == kAutoCameraModel;
    camera.camera.InitializeWithName(camera.choose_model ? "OPENCV" : models[c],
                                     1.2 * std::max(width, height), width,
                                     height);
    dataset->cameras.push_back(camera);
  }
  dataset->frameset_names = layout->frameset_names;
  dataset->reference_camera = layout->reference_camera;
  for (size_t i = 0; i < image_names.size(); ++i) {
    if (layout->images[i].camera_index < 0) continue;
    RigImage image;
    image.name = image_names[i];
    image.camera_index = layout->images[i].camera_index;
    image.frameset_index = layout->images[i].frameset_index;
    dataset->images.push_back(image);
  }
  dataset->frameset_times_s = FramesetTimes(*layout, dataset->reference_camera,
                                            options.timestamp_unit_s);
  return true;
}

// The known* methods (known, known_refine, known_ra): intrinsics from
// --RigCalibrator.intrinsics_path, else from the database cameras of the rig
// images (as set by feature_extractor --ImageReader.camera_params).
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
    } else if (intrinsics.Width() != camera.camera.Width() ||
               intrinsics.Height() != camera.camera.Height()) {
      // Focal length and principal point are in pixels of that size.
      *error = "the intrinsics of camera " + camera.name + " (" +
               (options.intrinsics_path.empty() ? "database"
                                                : options.intrinsics_path) +
               ") are for " + std::to_string(intrinsics.Width()) + "x" +
               std::to_string(intrinsics.Height()) +
               " images, but its images are " +
               std::to_string(camera.camera.Width()) + "x" +
               std::to_string(camera.camera.Height()) +
               ": give intrinsics calibrated at the images' size";
      return false;
    }
    camera.camera = intrinsics;
    camera.intrinsics_known = true;
    camera.choose_model = false;
  }
  return true;
}

// The image size of every rig image from its database camera (and the
// camera, for the known* methods). Fails for a rig image missing from the
// database and for one that is also a registered map image.
bool ReadRigImageCameras(const CalibrateOptions& options,
                         const DatabaseReader& database,
                         const colmap::Reconstruction& map,
                         const std::vector<std::string>& image_names,
                         std::vector<std::pair<int, int>>* image_sizes,
                         std::map<std::string, DatabaseCamera>* cameras_by_name,
                         std::string* error) {
  std::vector<std::string> missing;
  for (const std::string& name : image_names) {
    const DatabaseImage* image = database.FindImageWithName(name);
    if (image == nullptr) {
      missing.push_back(name);
      image_sizes->emplace_back(0, 0);
      continue;
    }
    DatabaseCamera camera;
    if (!database.ReadCamera(image->camera_id, &camera, error)) return false;
    image_sizes->emplace_back(static_cast<int>(camera.width),
                              static_cast<int>(camera.height));
    (*cameras_by_name)[name] = camera;
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
  return true;
}

// The frames of a COLMAP >= 3.12 database that group several of the rig
// images (COLMAP's rig_configurator was run) as per-image frame ids for the
// rig layout; empty if every frame holds one rig image at most (the trivial
// frames of feature_extractor), so that the framesets are found from the
// names.
RigLayoutOptions DatabaseFrames(const DatabaseReader& database,
                                const std::vector<std::string>& image_names) {
  std::map<colmap::image_t, int64_t> frame_of_image;
  for (const DatabaseFrame& frame : database.Frames()) {
    for (const colmap::image_t image_id : frame.image_ids) {
      frame_of_image[image_id] = frame.frame_id;
    }
  }
  RigLayoutOptions frames;
  std::map<int64_t, int> num_rig_images;
  bool grouped = false;
  for (const std::string& name : image_names) {
    const DatabaseImage* image = database.FindImageWithName(name);
    const auto frame = image != nullptr ? frame_of_image.find(image->image_id)
                                        : frame_of_image.end();
    frames.frame_ids.push_back(frame != frame_of_image.end() ? frame->second
                                                             : -1);
    if (frames.frame_ids.back() >= 0) {
      grouped |= ++num_rig_images[frames.frame_ids.back()] > 1;
    }
  }
  if (!grouped) return RigLayoutOptions();
  frames.frame_source =
      "the database's frames (COLMAP rig_configurator) in " + database.path();
  return frames;
}

// The known sensor_from_rig of the database rig that holds the most rig
// cameras (two at least, its reference camera among them): COLMAP's
// rig_configurator stores the poses of rig_config.json there. A rig camera
// is a database camera when all its images share one.
KnownRigPrior DatabaseRigPrior(
    const DatabaseReader& database, const RigDataset& dataset,
    const std::map<std::string, DatabaseCamera>& cameras_by_name) {
  std::map<colmap::camera_t, int> rig_camera_of;
  std::vector<colmap::camera_t> database_camera(dataset.cameras.size(),
                                                colmap::kInvalidCameraId);
  std::vector<bool> shared(dataset.cameras.size(), true);
  for (const RigImage& image : dataset.images) {
    const colmap::camera_t camera_id = cameras_by_name.at(image.name).camera_id;
    colmap::camera_t& known = database_camera[image.camera_index];
    if (known != colmap::kInvalidCameraId && known != camera_id) {
      shared[image.camera_index] = false;
    }
    known = camera_id;
  }
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    if (shared[c]) rig_camera_of[database_camera[c]] = static_cast<int>(c);
  }
  KnownRigPrior best;
  int best_num_known = 0;
  for (const DatabaseRig& rig : database.Rigs()) {
    const auto ref = rig_camera_of.find(rig.ref_camera_id);
    if (ref == rig_camera_of.end()) continue;
    KnownRigPrior prior;
    prior.reference_camera = ref->second;
    prior.cam_from_ref.assign(dataset.cameras.size(), std::nullopt);
    prior.cam_from_ref[ref->second] = Rigid3d();
    int num_known = 0;
    for (const DatabaseRig::Sensor& sensor : rig.cameras) {
      const auto camera = rig_camera_of.find(sensor.camera_id);
      if (camera == rig_camera_of.end() || !sensor.sensor_from_rig) continue;
      prior.cam_from_ref[camera->second] = sensor.sensor_from_rig;
      ++num_known;
    }
    if (num_known > best_num_known) {
      prior.source = "database " + database.path() + ", rig " +
                     std::to_string(rig.rig_id) + " (rig_sensors)";
      best = prior;
      best_num_known = num_known;
    }
  }
  return best;
}

// The database camera of every rig camera as a COLMAP 3.8 camera, for the
// known* methods without --RigCalibrator.intrinsics_path; fails naming the
// rig camera for a model this build cannot use.
bool RigDatabaseCameras(const CalibrateOptions& options,
                        const RigDataset& dataset,
                        const std::map<std::string, DatabaseCamera>& by_name,
                        std::vector<colmap::Camera>* cameras,
                        std::string* error) {
  cameras->assign(dataset.cameras.size(), colmap::Camera());
  if (!options.intrinsics_path.empty()) return true;
  for (const RigImage& image : dataset.images) {
    const DatabaseCamera& camera = by_name.at(image.name);
    std::string problem;
    if (!ToColmapCamera(camera, &(*cameras)[image.camera_index], &problem)) {
      *error = "method " + options.method + " needs the intrinsics of camera " +
               dataset.cameras[image.camera_index].name + " from database " +
               options.database_path + ", but its " + problem +
               ": give --RigCalibrator.intrinsics_path, or extract its "
               "features with a model of COLMAP 3.8 (e.g. "
               "--ImageReader.camera_model OPENCV or OPENCV_FISHEYE)";
      return false;
    }
  }
  return true;
}

// The 2D-3D correspondences of every dataset image, by localizing it
// against the map.
bool LocalizeDatasetImages(const CalibrateOptions& options,
                           const colmap::Reconstruction& map,
                           const DatabaseReader& database, RigDataset* dataset,
                           std::string* error) {
  MapLocalizerOptions localizer_options;
  if (!MakeLocalizerOptions(options, &localizer_options, error)) return false;
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

}  // namespace

bool LoadFromDatabase(const CalibrateOptions& options,
                      const colmap::Reconstruction& map, RigDataset* dataset,
                      RigLayout* layout, std::string* error,
                      KnownRigPrior* rig_prior) {
  std::vector<std::string> image_names;
  if (!ListImages(options.image_path, &image_names, error)) return false;
  DatabaseReader database;
  if (!database.Open(options.database_path, error)) return false;
  std::cout << "== Database " << options.database_path << ": "
            << database.SchemaDescription() << std::endl;
  std::vector<std::pair<int, int>> image_sizes;
  std::map<std::string, DatabaseCamera> cameras_by_name;
  if (!ReadRigImageCameras(options, database, map, image_names, &image_sizes,
                           &cameras_by_name, error) ||
      !MakeDataset(options,
                   "the rig images under --image_path " + options.image_path,
                   image_names, image_sizes, dataset, layout, error,
                   DatabaseFrames(database, image_names))) {
    return false;
  }
  if (rig_prior != nullptr) {
    *rig_prior = DatabaseRigPrior(database, *dataset, cameras_by_name);
  }
  if (options.KnownIntrinsics()) {
    std::vector<colmap::Camera> database_cameras;
    if (!RigDatabaseCameras(options, *dataset, cameras_by_name,
                            &database_cameras, error) ||
        !SetKnownIntrinsics(options, database_cameras, dataset, error)) {
      return false;
    }
  }
  if (!SetIntrinsicsRefinement(options, cameras_by_name, dataset, error)) {
    return false;
  }
  return LocalizeDatasetImages(options, map, database, dataset, error);
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
  if (options.KnownIntrinsics()) {
    if (!SetKnownIntrinsics(options, {}, dataset, error)) return false;
  }
  if (!SetIntrinsicsRefinement(options, {}, dataset, error)) return false;
  for (RigImage& image : dataset->images) {
    image.correspondences =
        std::move(images[index_by_name[image.name]].correspondences);
  }
  return true;
}

int AddMapImages(
    const colmap::Reconstruction& map,
    const std::unordered_set<colmap::camera_t>& placeholder_cameras,
    RigDataset* dataset) {
  std::map<colmap::camera_t, int> camera_index;
  int num_left_out = 0;
  for (const colmap::image_t image_id : map.RegImageIds()) {
    const colmap::Image& image = map.Image(image_id);
    if (placeholder_cameras.count(image.CameraId()) > 0) {
      ++num_left_out;
      continue;
    }
    const auto [it, inserted] = camera_index.emplace(
        image.CameraId(), static_cast<int>(dataset->map_cameras.size()));
    if (inserted) {
      dataset->map_cameras.push_back(map.Camera(image.CameraId()));
    }
    MapImage map_image;
    map_image.name = image.Name();
    map_image.image_id = image_id;
    map_image.camera_index = it->second;
    map_image.cam_from_world =
        Rigid3d(Eigen::Quaterniond(image.Qvec()(0), image.Qvec()(1),
                                   image.Qvec()(2), image.Qvec()(3))
                    .normalized(),
                image.Tvec());
    for (colmap::point2D_t k = 0; k < image.NumPoints2D(); ++k) {
      const colmap::Point2D& point2D = image.Point2D(k);
      if (point2D.HasPoint3D() && map.ExistsPoint3D(point2D.Point3DId())) {
        map_image.observations.push_back(
            {point2D.XY(), static_cast<int64_t>(point2D.Point3DId()), k});
      }
    }
    dataset->map_images.push_back(std::move(map_image));
  }
  for (const auto& [point3D_id, point3D] : map.Points3D()) {
    dataset->map_points3D[static_cast<int64_t>(point3D_id)] = point3D.XYZ();
  }
  return num_left_out;
}

}  // namespace rig_calibrator
