#include "src/calibration/rig_dataset.h"

namespace rig_calibrator {

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
  return true;
}

}  // namespace rig_calibrator
