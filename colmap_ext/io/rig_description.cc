#include "colmap_ext/io/rig_description.h"

namespace rig_calibrator {
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
