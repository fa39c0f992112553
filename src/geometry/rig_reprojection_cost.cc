#include "src/geometry/rig_reprojection_cost.h"

#include <colmap/base/camera_models.h>

namespace rig_calibrator {

ceres::CostFunction* CreateRigReprojectionCost(int model_id,
                                               const Eigen::Vector2d& observed,
                                               const Eigen::Vector3d* point3D) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel) \
  case colmap::CameraModel::kModelId:  \
    return new RigReprojectionCost<colmap::CameraModel>(observed, point3D);
    CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return nullptr;
  }
}

}  // namespace rig_calibrator
