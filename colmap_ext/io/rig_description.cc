#include "colmap_ext/io/rig_description.h"

namespace rig_calibrator {
namespace {

bool IsFinite(const Rigid3d& pose) {
  return pose.rotation.coeffs().allFinite() && pose.translation.allFinite();
}

}  // namespace

bool CheckCalibrationMatchesDataset(const RigDataset& dataset,
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
  return true;
}

RigDescription DescribeCalibratedRig(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes) {
  RigDescription rig;
  rig.reference_camera = dataset.reference_camera;
  const Rigid3d rig_from_ref =
      calibration.cam_from_rig[dataset.reference_camera].Inverse();
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    RigDescriptionCamera camera;
    camera.name = dataset.cameras[c].name;
    camera.image_prefix =
        image_prefixes.empty() ? camera.name + "/" : image_prefixes[c];
    if (calibration.camera_calibrated[c]) {
      camera.camera = calibration.cameras[c];
      camera.cam_from_rig = static_cast<int>(c) == dataset.reference_camera
                                ? Rigid3d()
                                : calibration.cam_from_rig[c] * rig_from_ref;
    }
    rig.cameras.push_back(std::move(camera));
  }
  return rig;
}

}  // namespace rig_calibrator
