#include "colmap_ext/io/model_writer.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <future>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/io/model_errors.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rig_description.h"
#include "colmap_ext/io/uncertainty_json.h"

namespace rig_calibrator {
namespace {

bool ValidIntrinsics(const colmap::Camera& camera) {
  return camera.Width() > 0 && camera.Height() > 0 && camera.VerifyParams() &&
         std::all_of(camera.Params().begin(), camera.Params().end(),
                     [](double p) { return std::isfinite(p); });
}

// COLMAP's rig_configurator (>= 3.12) makes a frame of the images with the
// same name after their camera's prefix. Framesets matched by timestamps pair
// different names, which it would not group as this calibration did.
int CountFramesWithDifferentKeys(const RigModel& rig_model,
                                 const RigDescription& rig) {
  std::unordered_map<colmap::camera_t, std::string> prefixes;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    prefixes[rig_model.rig.camera_ids[c]] = rig.cameras[c].image_prefix;
  }
  int count = 0;
  for (const ModelRig::Frame& frame : rig_model.rig.frames) {
    std::unordered_set<std::string> keys;
    for (const colmap::image_t image_id : frame.image_ids) {
      const colmap::Image& image = rig_model.model.Image(image_id);
      const std::string& prefix = prefixes[image.CameraId()];
      keys.insert(image.Name().compare(0, prefix.size(), prefix) == 0
                      ? image.Name().substr(prefix.size())
                      : image.Name());
    }
    count += keys.size() > 1 ? 1 : 0;
  }
  return count;
}

bool ModelFilesExist(const std::string& folder, const std::string& extension) {
  std::error_code ignored;
  for (const char* name : {"cameras", "images", "points3D"}) {
    if (!std::filesystem::is_regular_file(folder + "/" + name + extension,
                                          ignored)) {
      return false;
    }
  }
  return true;
}

// Moves the map points that the final bundle adjustment refined. A run from
// a correspondence file has no map points to move: its model has cameras and
// images only.
bool MoveRefinedPoints(const RigCalibration& calibration,
                       colmap::Reconstruction* model, std::string* error) {
  if (model->NumPoints3D() == 0) {
    return true;
  }
  for (const auto& [point3D_id, xyz] : calibration.refined_points3D) {
    if (point3D_id < 0 ||
        !model->ExistsPoint3D(static_cast<colmap::point3D_t>(point3D_id)) ||
        !xyz.allFinite()) {
      *error = "the refined point " + std::to_string(point3D_id) +
               " is not a map point or not finite";
      return false;
    }
    model->Point3D(static_cast<colmap::point3D_t>(point3D_id)).SetXYZ(xyz);
  }
  return true;
}

// Adds the registered image `image_id` of `rig_image` at cam_from_world, its
// points2D the correspondences' 2D points, and its inlier correspondences to
// map points as observations of those points (one per point).
void AddRigImage(const RigImage& rig_image, const std::vector<char>& inliers,
                 const colmap::image_t image_id,
                 const colmap::camera_t camera_id,
                 const Rigid3d& cam_from_world, colmap::Reconstruction* model) {
  colmap::Image image;
  image.SetImageId(image_id);
  image.SetName(rig_image.name);
  image.SetCameraId(camera_id);
  image.SetQvec(cam_from_world.Qvec());
  image.SetTvec(cam_from_world.translation);
  std::vector<Eigen::Vector2d> points2D;
  points2D.reserve(rig_image.correspondences.size());
  for (const Correspondence& correspondence : rig_image.correspondences) {
    points2D.push_back(correspondence.point2D);
  }
  image.SetPoints2D(points2D);
  model->AddImage(std::move(image));
  model->RegisterImage(image_id);

  std::unordered_set<colmap::point3D_t> observed;
  for (size_t k = 0; k < inliers.size(); ++k) {
    const int64_t point3D_id = rig_image.correspondences[k].point3D_id;
    if (!inliers[k] || point3D_id < 0) continue;
    const colmap::point3D_t id = static_cast<colmap::point3D_t>(point3D_id);
    if (model->ExistsPoint3D(id) && observed.insert(id).second) {
      model->AddObservation(
          id,
          colmap::TrackElement(image_id, static_cast<colmap::point2D_t>(k)));
    }
  }
}

// The calibrated intrinsics of every camera, the dataset's initial ones for
// a camera that is not calibrated; false unless all are valid with a size.
bool ModelCameras(const RigDataset& dataset, const RigCalibration& calibration,
                  std::vector<colmap::Camera>* cameras, std::string* error) {
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    cameras->push_back(calibration.camera_calibrated[c]
                           ? calibration.cameras[c]
                           : dataset.cameras[c].camera);
    if (!ValidIntrinsics(cameras->back())) {
      *error = "the camera " + dataset.cameras[c].name +
               " has invalid intrinsics or no image size";
      return false;
    }
  }
  return true;
}

}  // namespace

namespace {

// Keep clear of kInvalidCameraId/kInvalidImageId (the uint32 maximum) and
// leave room for the rig frame ids that follow the image ids.
bool CheckRoomForRigIds(const RigDataset& dataset,
                        colmap::camera_t max_camera_id,
                        colmap::image_t max_image_id, std::string* error) {
  constexpr uint64_t kMaxId = std::numeric_limits<uint32_t>::max() / 2;
  if (max_camera_id + static_cast<uint64_t>(dataset.cameras.size()) >= kMaxId ||
      max_image_id + 2 * static_cast<uint64_t>(dataset.images.size()) >=
          kMaxId) {
    *error = "the map's camera or image ids are too large to add the rig";
    return false;
  }
  return true;
}

// Adds the cameras after the map's (ids max_camera_id + 1, ...) and sets the
// rig: the rig frame is the reference camera's frame, cam_from_ref =
// cam_from_rig * (ref_from_rig)^-1 (unset for an uncalibrated camera).
void AddRigCameras(const RigDataset& dataset, const RigCalibration& calibration,
                   std::vector<colmap::Camera> cameras,
                   colmap::camera_t max_camera_id,
                   colmap::Reconstruction* model, ModelRig* rig) {
  const Rigid3d& ref_from_rig =
      calibration.cam_from_rig[dataset.reference_camera];
  *rig = ModelRig();
  rig->reference_camera = dataset.reference_camera;
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    cameras[c].SetCameraId(max_camera_id + 1 +
                           static_cast<colmap::camera_t>(c));
    model->AddCamera(cameras[c]);
    rig->camera_ids.push_back(cameras[c].CameraId());
    if (!calibration.camera_calibrated[c]) {
      rig->cam_from_rig.emplace_back();
    } else if (static_cast<int>(c) == dataset.reference_camera) {
      rig->cam_from_rig.emplace_back(Rigid3d());
    } else {
      rig->cam_from_rig.emplace_back(calibration.cam_from_rig[c] *
                                     ref_from_rig.Inverse());
    }
  }
}

// Adds every used image of a calibrated camera in a posed frameset (ids
// max_image_id + 1 + dataset index) and its frame: ref_from_world =
// ref_from_rig * rig_from_world, which leaves every cam_from_world unchanged.
bool AddRigFrames(const colmap::Reconstruction& map, const RigDataset& dataset,
                  const RigCalibration& calibration,
                  colmap::image_t max_image_id, RigModel* rig_model,
                  std::string* error) {
  std::unordered_set<std::string> map_names;
  for (const auto& [image_id, image] : map.Images()) {
    map_names.insert(image.Name());
  }
  const Rigid3d& ref_from_rig =
      calibration.cam_from_rig[dataset.reference_camera];
  ModelRig& rig = rig_model->rig;
  std::vector<int> frame_of_frameset(dataset.frameset_names.size(), -1);
  rig_model->image_ids.assign(dataset.images.size(), colmap::kInvalidImageId);
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& rig_image = dataset.images[i];
    const int c = rig_image.camera_index;
    const int f = rig_image.frameset_index;
    if (!calibration.images[i].used || !rig.cam_from_rig[c] ||
        !calibration.rig_from_world[f]) {
      continue;
    }
    if (map_names.count(rig_image.name) > 0) {
      *error =
          "the rig image " + rig_image.name + " has the name of a map image";
      return false;
    }
    if (frame_of_frameset[f] < 0) {
      frame_of_frameset[f] = static_cast<int>(rig.frames.size());
      rig.frames.push_back({ref_from_rig * *calibration.rig_from_world[f], {}});
    }
    ModelRig::Frame& frame = rig.frames[frame_of_frameset[f]];
    const Rigid3d cam_from_world = *rig.cam_from_rig[c] * frame.rig_from_world;

    const colmap::image_t image_id =
        max_image_id + 1 + static_cast<colmap::image_t>(i);
    AddRigImage(rig_image, calibration.images[i].inlier_mask, image_id,
                rig.camera_ids[c], cam_from_world, &rig_model->model);
    rig_model->image_ids[i] = image_id;
    frame.image_ids.push_back(image_id);
  }
  return true;
}

// The final adjustment's map results (adjusted map poses and intrinsics,
// rejected map observations), then every point's error recomputed, so that
// the model's stored errors are its own (model_errors.h). Observations behind
// their camera are dropped (COLMAP would count them as infinite).
void ApplyMapResults(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::unordered_set<colmap::image_t>& placeholder_images,
    colmap::Reconstruction* model, int64_t* num_dropped_map_observations) {
  *num_dropped_map_observations = 0;
  if (!calibration.map_cam_from_world.empty()) {
    for (const colmap::Camera& camera : calibration.map_cameras) {
      if (model->ExistsCamera(camera.CameraId())) {
        model->Camera(camera.CameraId()).SetParams(camera.Params());
      }
    }
    for (size_t i = 0; i < dataset.map_images.size(); ++i) {
      const MapImage& map_image = dataset.map_images[i];
      const colmap::image_t image_id =
          static_cast<colmap::image_t>(map_image.image_id);
      if (!model->ExistsImage(image_id)) continue;
      colmap::Image& image = model->Image(image_id);
      image.SetQvec(calibration.map_cam_from_world[i].Qvec());
      image.SetTvec(calibration.map_cam_from_world[i].translation);
      for (size_t k = 0; k < map_image.observations.size(); ++k) {
        const colmap::point2D_t point2D_idx =
            map_image.observations[k].point2D_idx;
        if (calibration.map_observation_rejected[i][k] &&
            point2D_idx < image.NumPoints2D() &&
            image.Point2D(point2D_idx).HasPoint3D()) {
          model->DeleteObservation(image_id, point2D_idx);
          ++*num_dropped_map_observations;
        }
      }
    }
  }
  model->FilterObservationsWithNegativeDepth();
  RecomputePointErrors(model, placeholder_images);
}

}  // namespace

bool BuildRigModel(
    const colmap::Reconstruction& map, const RigDataset& dataset,
    const RigCalibration& calibration, RigModel* rig_model, std::string* error,
    const std::unordered_set<colmap::camera_t>& placeholder_map_cameras) {
  if (!ValidateCalibration(dataset, calibration, error)) {
    return false;
  }
  std::vector<colmap::Camera> cameras;
  if (!ModelCameras(dataset, calibration, &cameras, error)) return false;
  const colmap::camera_t max_camera_id = MaxCameraId(map);
  const colmap::image_t max_image_id = MaxImageId(map);
  if (!CheckRoomForRigIds(dataset, max_camera_id, max_image_id, error)) {
    return false;
  }
  rig_model->model = map;
  if (!MoveRefinedPoints(calibration, &rig_model->model, error)) {
    return false;
  }
  AddRigCameras(dataset, calibration, std::move(cameras), max_camera_id,
                &rig_model->model, &rig_model->rig);
  if (!AddRigFrames(map, dataset, calibration, max_image_id, rig_model,
                    error)) {
    return false;
  }
  std::unordered_set<colmap::image_t> map_image_ids, placeholder_images;
  for (const colmap::image_t image_id : map.RegImageIds()) {
    if (placeholder_map_cameras.count(map.Image(image_id).CameraId()) > 0) {
      placeholder_images.insert(image_id);
    } else {
      map_image_ids.insert(image_id);
    }
  }
  ApplyMapResults(dataset, calibration, placeholder_images, &rig_model->model,
                  &rig_model->num_dropped_map_observations);
  if (!map_image_ids.empty()) {
    rig_model->map_input_errors = ComputeReprojectionStats(map, map_image_ids);
    rig_model->map_output_errors =
        ComputeReprojectionStats(rig_model->model, map_image_ids);
  }
  return true;
}

namespace {

// What COLMAP's rig tools will make of the exported configs: the snapshots
// COLMAP 3.8's rig_bundle_adjuster will group (by name) where they differ
// from the framesets, and the frames rig_configurator (>= 3.12) will miss.
std::vector<std::string> RigConfigNotes(const RigModel& rig_model,
                                        const RigDescription& rig,
                                        const bool reference_calibrated) {
  std::vector<std::string> new_notes;
  if (reference_calibrated) {
    const RigBundleAdjusterGrouping grouping =
        PredictRigBundleAdjusterGrouping(rig, rig_model.model);
    int num_multi_image_frames = 0;
    for (const ModelRig::Frame& frame : rig_model.rig.frames) {
      num_multi_image_frames += frame.image_ids.size() > 1 ? 1 : 0;
    }
    if (grouping.num_multi_image_snapshots != num_multi_image_frames ||
        !grouping.problems.empty()) {
      new_notes.push_back(
          std::string(kRigBundleAdjusterConfigFile) +
          ": COLMAP 3.8 rig_bundle_adjuster groups images by name and will "
          "see " +
          std::to_string(grouping.num_multi_image_snapshots) +
          " snapshots with two images or more, where this calibration has " +
          std::to_string(num_multi_image_frames) + " such framesets");
    }
    for (const std::string& problem : grouping.problems) {
      new_notes.push_back(
          std::string(kRigBundleAdjusterConfigFile) +
          ": COLMAP 3.8 rig_bundle_adjuster would abort: " + problem);
    }
  } else {
    new_notes.push_back(std::string(kRigBundleAdjusterConfigFile) +
                        " is not written: the reference camera is not "
                        "calibrated");
  }
  const int num_renamed_frames = CountFramesWithDifferentKeys(rig_model, rig);
  if (num_renamed_frames > 0) {
    new_notes.push_back(
        std::string(kRigConfigFile) + ": " +
        std::to_string(num_renamed_frames) +
        " framesets pair images with different names after the camera "
        "prefix (timestamp matching); COLMAP's rig_configurator groups frames "
        "by identical names and will not find them (frames.* hold them)");
  }

  return new_notes;
}

}  // namespace

namespace {

// Everything written into the output folder, built before the folder is
// touched (what can fail for reasons other than the file system fails here).
struct RigOutputContents {
  bool binary = true;
  RigModel rig_model;
  ColmapRigsAndFrames rigs_frames;
  RigDescription rig;
  bool reference_calibrated = false;
  std::vector<std::string> notes;
  std::vector<CameraRecord> newer_model_map_cameras;
  std::optional<MapImagesSummary> map_images;
};

bool BuildRigOutputContents(const colmap::Reconstruction& map,
                            const RigDataset& dataset,
                            const RigCalibration& calibration,
                            const std::vector<std::string>& camera_prefixes,
                            const RigOutputOptions& options,
                            RigOutputContents* contents, std::string* error) {
  std::string output_type = options.output_type;
  std::transform(output_type.begin(), output_type.end(), output_type.begin(),
                 [](unsigned char c) { return std::toupper(c); });
  if (output_type != "BIN" && output_type != "TXT") {
    *error = "output_type must be BIN or TXT, not " + options.output_type;
    return false;
  }
  contents->binary = output_type == "BIN";
  contents->newer_model_map_cameras = options.newer_model_map_cameras;
  if (!camera_prefixes.empty() &&
      camera_prefixes.size() != dataset.cameras.size()) {
    *error = "one camera prefix per camera is needed";
    return false;
  }
  std::unordered_set<colmap::camera_t> placeholder_map_cameras;
  for (const CameraRecord& camera : options.newer_model_map_cameras) {
    placeholder_map_cameras.insert(camera.camera_id);
  }
  if (!BuildRigModel(map, dataset, calibration, &contents->rig_model, error,
                     placeholder_map_cameras) ||
      !BuildRigsAndFrames(contents->rig_model.model, contents->rig_model.rig,
                          &contents->rigs_frames, error)) {
    return false;
  }
  RigDescription& rig = contents->rig;
  rig = DescribeCalibratedRig(dataset, calibration, camera_prefixes);
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    if (rig.cameras[c].camera) {
      rig.cameras[c].camera->SetCameraId(contents->rig_model.rig.camera_ids[c]);
    }
  }
  contents->reference_calibrated =
      rig.cameras[rig.reference_camera].camera.has_value();
  contents->notes =
      RigConfigNotes(contents->rig_model, rig, contents->reference_calibrated);
  const RigModel& rig_model = contents->rig_model;
  if (rig_model.map_input_errors.num_observations > 0) {
    MapImagesSummary& map_images = contents->map_images.emplace();
    map_images.input_mean_error_px = rig_model.map_input_errors.mean_px;
    map_images.output_mean_error_px = rig_model.map_output_errors.mean_px;
    map_images.input_max_error_px = rig_model.map_input_errors.max_px;
    map_images.output_max_error_px = rig_model.map_output_errors.max_px;
    map_images.num_input_observations =
        rig_model.map_input_errors.num_observations;
    map_images.num_output_observations =
        rig_model.map_output_errors.num_observations;
    map_images.num_dropped_observations =
        rig_model.num_dropped_map_observations;
  }
  // The note only when the map images took part in the final adjustment
  // (the JSON's map_images is there whenever there is a map).
  if (contents->map_images && !calibration.map_cam_from_world.empty()) {
    const MapImagesSummary& map_images = *contents->map_images;
    std::ostringstream note;
    note << "map images: mean reprojection error " << std::setprecision(3)
         << map_images.input_mean_error_px << " px in the input map, "
         << map_images.output_mean_error_px << " px in the output model (max "
         << map_images.input_max_error_px << " -> "
         << map_images.output_max_error_px << " px); "
         << map_images.num_dropped_observations
         << " map observations that no longer fit their refined points "
            "dropped";
    contents->notes.push_back(note.str());
  }
  return true;
}

// Writes the files into `folder`; notes of the camchain writer are added to
// contents->notes, which the summary then lists.
bool WriteRigOutputFiles(const std::string& folder, const RigDataset& dataset,
                         const CalibrationSummary& summary,
                         RigOutputContents* contents, std::string* error) {
  const bool binary = contents->binary;
  if (binary) {
    contents->rig_model.model.WriteBinary(folder);
  } else {
    contents->rig_model.model.WriteText(folder);
  }
  if (!ModelFilesExist(folder, binary ? ".bin" : ".txt")) {
    *error = "cannot write the COLMAP model into " + folder;
    return false;
  }
  if (!RestoreNewerModelCameras(folder, binary,
                                contents->newer_model_map_cameras, error)) {
    return false;
  }
  const RigDescription& rig = contents->rig;
  if (!WriteRigsAndFrames(folder, contents->rigs_frames, binary, error) ||
      !WriteRigConfigJson(folder + "/" + kRigConfigFile, rig, error)) {
    return false;
  }
  if (contents->reference_calibrated &&
      !WriteRigBundleAdjusterConfig(folder + "/" + kRigBundleAdjusterConfigFile,
                                    rig, error)) {
    return false;
  }
  std::string camchain_error;
  RigDescription commented_rig = rig;
  AddUncertaintyComments(summary.uncertainty, &commented_rig);
  for (size_t c = 0; c < commented_rig.cameras.size() &&
                     c < summary.cameras.size();
       ++c) {
    commented_rig.cameras[c].timing = summary.cameras[c].timing;
    if (c < summary.timestamp_offsets_s.size()) {
      commented_rig.cameras[c].timestamp_offset_s =
          summary.timestamp_offsets_s[c];
    }
  }
  if (!WriteCamchainYaml(folder + "/" + kCamchainFile, commented_rig,
                         &contents->notes, &camchain_error)) {
    contents->notes.push_back(std::string(kCamchainFile) +
                              " is not written: " + camchain_error);
  }
  CalibrationSummary final_summary = summary;
  final_summary.map_images = contents->map_images;
  final_summary.diagnostics.insert(final_summary.diagnostics.end(),
                                   contents->notes.begin(),
                                   contents->notes.end());
  return WriteCalibrationSummaryJson(folder + "/" + kSummaryFile, final_summary,
                                     error) &&
         WriteTimingsJson(folder + "/" + kTimingsFile, final_summary, error);
}

}  // namespace

bool WriteRigOutput(const std::string& output_path,
                    const colmap::Reconstruction& map,
                    const RigDataset& dataset,
                    const RigCalibration& calibration,
                    const std::vector<std::string>& camera_prefixes,
                    const CalibrationSummary& summary,
                    const RigOutputOptions& options,
                    std::vector<std::string>* notes, std::string* error) {
  RigOutputContents contents;
  if (!BuildRigOutputContents(map, dataset, calibration, camera_prefixes,
                              options, &contents, error)) {
    return false;
  }
  OutputFolderOptions folder_options;
  folder_options.overwrite = options.overwrite;
  folder_options.input_paths = options.input_paths;
  if (!WriteFolderAtomically(
          output_path, folder_options,
          [&](const std::string& folder, std::string* write_error) {
            // The correspondence file, the largest by far, is written on a
            // thread of its own while the other files and the report are;
            // the report reads it only for a model without points, and then
            // waits for it. Errors in the order of a sequential write: the
            // files', the correspondence file's, the report's.
            std::string correspondence_error;
            std::future<bool> correspondences = std::async(
                std::launch::async, [&] {
                  return WriteCorrespondenceFile(
                      folder + "/" + kCorrespondencesFile,
                      DatasetCorrespondences(dataset), &correspondence_error);
                });
            if (!WriteRigOutputFiles(folder, dataset, summary, &contents,
                                     write_error)) {
              correspondences.wait();
              return false;
            }
            if (contents.rig_model.model.NumPoints3D() == 0) {
              correspondences.wait();
            }
            std::string report_error;
            const bool finished = !options.finish_folder ||
                                  options.finish_folder(folder, &report_error);
            if (!correspondences.get()) {
              *write_error = correspondence_error;
              return false;
            }
            if (!finished) *write_error = report_error;
            return finished;
          },
          error)) {
    return false;
  }
  if (notes != nullptr) {
    notes->insert(notes->end(), contents.notes.begin(), contents.notes.end());
  }
  return true;
}

}  // namespace rig_calibrator
