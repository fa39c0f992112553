#include "src/rig/rig_dataset.h"

#include <cmath>

namespace rig_calibrator {
namespace {

bool IsFinite(const Rigid3d& pose) {
  return pose.rotation.coeffs().allFinite() && pose.translation.allFinite();
}

// The map part of ValidateCalibration.
bool ValidateMapResults(const RigDataset& dataset,
                        const RigCalibration& calibration, std::string* error) {
  if (calibration.map_cameras.empty() &&
      calibration.map_cam_from_world.empty() &&
      calibration.map_observation_rejected.empty()) {
    return true;
  }
  if (calibration.map_cameras.size() != dataset.map_cameras.size() ||
      calibration.map_cam_from_world.size() != dataset.map_images.size() ||
      calibration.map_observation_rejected.size() !=
          dataset.map_images.size()) {
    *error = "the calibration's map results do not match the dataset's " +
             std::to_string(dataset.map_cameras.size()) + " map cameras and " +
             std::to_string(dataset.map_images.size()) + " map images";
    return false;
  }
  for (size_t i = 0; i < dataset.map_images.size(); ++i) {
    const MapImage& image = dataset.map_images[i];
    if (!IsFinite(calibration.map_cam_from_world[i]) ||
        calibration.map_observation_rejected[i].size() !=
            image.observations.size()) {
      *error = "the map image " + image.name +
               " has a non-finite pose or a wrong number of rejection flags";
      return false;
    }
  }
  return true;
}

}  // namespace

bool ValidateDataset(const RigDataset& dataset, std::string* error) {
  const int num_cameras = static_cast<int>(dataset.cameras.size());
  if (num_cameras < 2) {
    *error = "a rig needs at least two cameras, the dataset has " +
             std::to_string(num_cameras);
    return false;
  }
  if (dataset.reference_camera < 0 || dataset.reference_camera >= num_cameras) {
    *error = "the reference camera index " +
             std::to_string(dataset.reference_camera) + " is not a camera";
    return false;
  }
  for (const RigCamera& camera : dataset.cameras) {
    if (camera.camera.Width() == 0 || camera.camera.Height() == 0 ||
        !camera.camera.VerifyParams()) {
      *error = "camera " + camera.name +
               " has no image size or invalid parameters for model " +
               camera.camera.ModelName();
      return false;
    }
  }
  if (!dataset.frameset_times_s.empty()) {
    if (dataset.frameset_times_s.size() != dataset.frameset_names.size()) {
      *error = "the dataset has " +
               std::to_string(dataset.frameset_times_s.size()) +
               " frameset times for " +
               std::to_string(dataset.frameset_names.size()) + " framesets";
      return false;
    }
    for (size_t f = 0; f < dataset.frameset_times_s.size(); ++f) {
      const double time = dataset.frameset_times_s[f];
      if (!std::isfinite(time) ||
          (f > 0 && !(time > dataset.frameset_times_s[f - 1]))) {
        *error = "the time of frameset " + dataset.frameset_names[f] +
                 " is not finite or not after the previous frameset's";
        return false;
      }
    }
  }
  for (const RigImage& image : dataset.images) {
    if (image.camera_index < 0 || image.camera_index >= num_cameras ||
        image.frameset_index < 0 ||
        image.frameset_index >=
            static_cast<int>(dataset.frameset_names.size())) {
      *error = "image " + image.name + " has no valid camera or frameset";
      return false;
    }
    for (const Correspondence& correspondence : image.correspondences) {
      if (!correspondence.point2D.allFinite() ||
          !correspondence.point3D.allFinite()) {
        *error = "image " + image.name + " has a non-finite correspondence";
        return false;
      }
    }
  }
  for (const colmap::Camera& camera : dataset.map_cameras) {
    if (!camera.VerifyParams()) {
      *error = "a map camera (id " + std::to_string(camera.CameraId()) +
               ") has invalid parameters for model " + camera.ModelName();
      return false;
    }
  }
  for (const MapImage& image : dataset.map_images) {
    if (image.camera_index < 0 ||
        image.camera_index >= static_cast<int>(dataset.map_cameras.size()) ||
        !IsFinite(image.cam_from_world)) {
      *error = "map image " + image.name + " has no valid camera or pose";
      return false;
    }
    for (const MapObservation& observation : image.observations) {
      if (!observation.point2D.allFinite() ||
          dataset.map_points3D.count(observation.point3D_id) == 0) {
        *error = "map image " + image.name +
                 " has a non-finite observation or one of an unknown point";
        return false;
      }
    }
  }
  for (const auto& [point3D_id, point] : dataset.map_points3D) {
    if (!point.allFinite()) {
      *error = "map point " + std::to_string(point3D_id) + " is not finite";
      return false;
    }
  }
  return true;
}

bool ValidateCalibration(const RigDataset& dataset,
                         const RigCalibration& calibration,
                         std::string* error) {
  if (!ValidateDataset(dataset, error)) return false;
  const size_t num_cameras = dataset.cameras.size();
  const size_t num_framesets = dataset.frameset_names.size();
  if (calibration.cameras.size() != num_cameras ||
      calibration.cam_from_rig.size() != num_cameras ||
      calibration.camera_calibrated.size() != num_cameras ||
      calibration.rig_from_world.size() != num_framesets ||
      calibration.images.size() != dataset.images.size()) {
    *error = "the calibration does not match the dataset: it has " +
             std::to_string(calibration.cameras.size()) + " cameras, " +
             std::to_string(calibration.rig_from_world.size()) +
             " framesets and " + std::to_string(calibration.images.size()) +
             " images for " + std::to_string(num_cameras) + ", " +
             std::to_string(num_framesets) + " and " +
             std::to_string(dataset.images.size());
    return false;
  }
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!IsFinite(calibration.cam_from_rig[c])) {
      *error = "the camera " + dataset.cameras[c].name +
               " has a non-finite cam_from_rig";
      return false;
    }
  }
  for (size_t f = 0; f < num_framesets; ++f) {
    if (calibration.rig_from_world[f] &&
        !IsFinite(*calibration.rig_from_world[f])) {
      *error = "the frameset " + dataset.frameset_names[f] +
               " has a non-finite rig_from_world";
      return false;
    }
  }
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    const std::vector<char>& mask = calibration.images[i].inlier_mask;
    if (!mask.empty() && mask.size() != image.correspondences.size()) {
      *error = "the image " + image.name + " has " +
               std::to_string(mask.size()) + " inlier flags for " +
               std::to_string(image.correspondences.size()) +
               " correspondences";
      return false;
    }
  }
  return ValidateMapResults(dataset, calibration, error);
}

}  // namespace rig_calibrator
