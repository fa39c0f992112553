#include "colmap_ext/io/colmap_camera_models.h"

#include <colmap/base/camera_models.h>

namespace rig_calibrator {
namespace {

// The models added after COLMAP 3.8, from the COLMAP sources of 3.11 - 4.1
// (src/colmap/sensor/models.h): id, name, number of parameters, first
// version.
struct NewerCameraModel {
  int id;
  const char* name;
  int num_params;
  const char* since;
};

constexpr NewerCameraModel kNewerCameraModels[] = {
    // fx, fy, cx, cy, k0-k5, p0, p1, s0-s3
    {11, "RAD_TAN_THIN_PRISM_FISHEYE", 16, "3.11"},
    {12, "SIMPLE_DIVISION", 4, "4.0"},  // f, cx, cy, k
    {13, "DIVISION", 5, "4.0"},         // fx, fy, cx, cy, k
    {14, "SIMPLE_FISHEYE", 3, "4.0"},   // f, cx, cy
    {15, "FISHEYE", 4, "4.0"},          // fx, fy, cx, cy
    {16, "EUCM", 6, "4.1"},             // fx, fy, cx, cy, alpha, beta
    {17, "EQUIRECTANGULAR", 2, "4.1"},  // width, height
};

const NewerCameraModel* FindNewerModel(const int model_id) {
  for (const NewerCameraModel& model : kNewerCameraModels) {
    if (model.id == model_id) return &model;
  }
  return nullptr;
}

}  // namespace

std::string ColmapCameraModelName(const int model_id) {
  if (colmap::ExistsCameraModelWithId(model_id)) {
    return colmap::CameraModelIdToName(model_id);
  }
  const NewerCameraModel* model = FindNewerModel(model_id);
  return model != nullptr ? model->name : "UNKNOWN";
}

int ColmapCameraModelNumParams(const int model_id) {
  if (colmap::ExistsCameraModelWithId(model_id)) {
    return static_cast<int>(colmap::CameraModelNumParams(model_id));
  }
  const NewerCameraModel* model = FindNewerModel(model_id);
  return model != nullptr ? model->num_params : -1;
}

int ColmapCameraModelIdFromName(const std::string& name) {
  if (colmap::ExistsCameraModelWithName(name)) {
    return colmap::CameraModelNameToId(name);
  }
  for (const NewerCameraModel& model : kNewerCameraModels) {
    if (name == model.name) return model.id;
  }
  return -1;
}

std::string DescribeColmapCameraModel(const int model_id) {
  const NewerCameraModel* model = FindNewerModel(model_id);
  return ColmapCameraModelName(model_id) + " (model id " +
         std::to_string(model_id) +
         (model != nullptr ? std::string(", COLMAP >= ") + model->since
                           : std::string()) +
         ")";
}

}  // namespace rig_calibrator
