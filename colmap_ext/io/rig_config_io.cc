#include "colmap_ext/io/rig_config_io.h"

#include <colmap/base/camera_models.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "colmap_ext/io/atomic_output.h"

namespace rig_calibrator {
namespace {

using Json = nlohmann::ordered_json;

Json QuaternionJson(const Eigen::Quaterniond& q) {
  return Json::array({q.w(), q.x(), q.y(), q.z()});
}

Json VectorJson(const Eigen::Vector3d& v) {
  return Json::array({v.x(), v.y(), v.z()});
}

bool CheckWritable(const RigDescription& rig, std::string* error) {
  if (rig.reference_camera < 0 ||
      rig.reference_camera >= static_cast<int>(rig.cameras.size())) {
    *error = "the rig's reference camera index is out of range";
    return false;
  }
  for (const RigDescriptionCamera& camera : rig.cameras) {
    if (camera.image_prefix.empty()) {
      *error = "the camera " + camera.name + " has no image prefix";
      return false;
    }
    if (camera.cam_from_rig &&
        (!camera.cam_from_rig->rotation.coeffs().allFinite() ||
         !camera.cam_from_rig->translation.allFinite())) {
      *error = "the camera " + camera.name + " has a non-finite cam_from_rig";
      return false;
    }
    if (camera.camera &&
        (!camera.camera->VerifyParams() ||
         !std::all_of(camera.camera->Params().begin(),
                      camera.camera->Params().end(),
                      [](double p) { return std::isfinite(p); }))) {
      *error = "the camera " + camera.name + " has invalid intrinsics";
      return false;
    }
  }
  return true;
}

// Reads a JSON array of exactly `size` numbers.
bool ReadNumbers(const Json& value, size_t size, std::vector<double>* numbers) {
  if (!value.is_array() || (size > 0 && value.size() != size)) {
    return false;
  }
  numbers->clear();
  for (const Json& element : value) {
    if (!element.is_number()) return false;
    numbers->push_back(element.get<double>());
    if (!std::isfinite(numbers->back())) return false;
  }
  return true;
}

// cam_from_rig_rotation/_translation (both or neither; none for the reference
// sensor, whose pose is the identity).
bool ReadRigCameraPose(const Json& node, const std::string& where,
                       bool ref_sensor, RigDescriptionCamera* camera,
                       std::string* error) {
  const bool has_rotation = node.contains("cam_from_rig_rotation");
  const bool has_translation = node.contains("cam_from_rig_translation");
  if (has_rotation != has_translation) {
    *error = where +
             ": cam_from_rig_rotation and cam_from_rig_translation must be "
             "given together";
    return false;
  }
  if (has_rotation) {
    if (ref_sensor) {
      *error = where + ": the reference sensor must not have a pose";
      return false;
    }
    std::vector<double> q;
    std::vector<double> t;
    if (!ReadNumbers(node["cam_from_rig_rotation"], 4, &q) ||
        !ReadNumbers(node["cam_from_rig_translation"], 3, &t)) {
      *error = where +
               ": cam_from_rig_rotation must be 4 numbers [w, x, y, z] and "
               "cam_from_rig_translation 3 numbers";
      return false;
    }
    const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
    if (rotation.norm() < 1e-6) {
      *error = where + ": cam_from_rig_rotation is not a rotation";
      return false;
    }
    camera->cam_from_rig = Rigid3d(rotation, Eigen::Vector3d(t[0], t[1], t[2]));
  } else if (ref_sensor) {
    camera->cam_from_rig = Rigid3d();
  }
  return true;
}

// camera_model_name and camera_params (both or neither).
bool ReadRigCameraIntrinsics(const Json& node, const std::string& where,
                             RigDescriptionCamera* camera, std::string* error) {
  const bool has_model = node.contains("camera_model_name");
  const bool has_params = node.contains("camera_params");
  if (has_model != has_params) {
    *error =
        where + ": camera_model_name and camera_params must be given together";
    return false;
  }
  if (has_model) {
    if (!node["camera_model_name"].is_string() ||
        !colmap::ExistsCameraModelWithName(
            node["camera_model_name"].get<std::string>())) {
      *error = where + ": unknown camera_model_name " +
               node["camera_model_name"].dump();
      return false;
    }
    colmap::Camera intrinsics;
    intrinsics.SetModelIdFromName(node["camera_model_name"].get<std::string>());
    std::vector<double> params;
    if (!ReadNumbers(node["camera_params"], 0, &params)) {
      *error = where + ": camera_params must be a list of numbers";
      return false;
    }
    intrinsics.SetParams(params);
    if (!intrinsics.VerifyParams()) {
      *error =
          where + ": " + intrinsics.ModelName() + " takes " +
          std::to_string(colmap::CameraModelNumParams(intrinsics.ModelId())) +
          " camera_params (" + intrinsics.ParamsInfo() + "), not " +
          std::to_string(params.size());
      return false;
    }
    camera->camera = intrinsics;
  }
  return true;
}

bool ReadRigCamera(const Json& node, const std::string& where,
                   RigDescriptionCamera* camera, bool* ref_sensor,
                   std::string* error) {
  if (!node.is_object()) {
    *error = where + " is not an object";
    return false;
  }
  if (!node.contains("image_prefix") || !node["image_prefix"].is_string() ||
      node["image_prefix"].get<std::string>().empty()) {
    *error = where + " has no image_prefix";
    return false;
  }
  camera->image_prefix = node["image_prefix"].get<std::string>();
  camera->name = camera->image_prefix;
  if (camera->name.size() > 1 && camera->name.back() == '/') {
    camera->name.pop_back();
  }
  *ref_sensor = false;
  if (node.contains("ref_sensor")) {
    if (!node["ref_sensor"].is_boolean()) {
      *error = where + ": ref_sensor must be true or false";
      return false;
    }
    *ref_sensor = node["ref_sensor"].get<bool>();
  }

  return ReadRigCameraPose(node, where, *ref_sensor, camera, error) &&
         ReadRigCameraIntrinsics(node, where, camera, error);
}

}  // namespace

bool WriteRigConfigJson(const std::string& path, const RigDescription& rig,
                        std::string* error) {
  if (!CheckWritable(rig, error)) {
    return false;
  }
  Json cameras = Json::array();
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const RigDescriptionCamera& camera = rig.cameras[c];
    Json node;
    node["image_prefix"] = camera.image_prefix;
    if (static_cast<int>(c) == rig.reference_camera) {
      node["ref_sensor"] = true;
    } else if (camera.cam_from_rig) {
      node["cam_from_rig_rotation"] =
          QuaternionJson(camera.cam_from_rig->rotation);
      node["cam_from_rig_translation"] =
          VectorJson(camera.cam_from_rig->translation);
    }
    if (camera.camera) {
      node["camera_model_name"] = camera.camera->ModelName();
      node["camera_params"] = camera.camera->Params();
    }
    cameras.push_back(node);
  }
  Json rigs = Json::array({Json{{"cameras", cameras}}});
  return WriteFileAtomically(
      path, rigs.dump(2, ' ', false, Json::error_handler_t::replace) + "\n",
      error);
}

bool ReadRigConfigJson(const std::string& path,
                       std::vector<RigDescription>* rigs, std::string* error) {
  rigs->clear();
  std::ifstream file(path);
  if (!file) {
    *error = "cannot open the rig config " + path;
    return false;
  }
  Json root;
  try {
    root = Json::parse(file);
  } catch (const Json::exception& e) {
    *error = "the rig config " + path + " is not valid JSON: " + e.what();
    return false;
  }
  if (!root.is_array() || root.empty()) {
    *error = "the rig config " + path + " must be a non-empty list of rigs";
    return false;
  }
  for (size_t r = 0; r < root.size(); ++r) {
    const std::string rig_where = path + ": rig " + std::to_string(r);
    const Json& rig_node = root[r];
    if (!rig_node.is_object() || !rig_node.contains("cameras") ||
        !rig_node["cameras"].is_array() || rig_node["cameras"].empty()) {
      *error = rig_where + " has no list of cameras";
      return false;
    }
    RigDescription rig;
    rig.reference_camera = -1;
    const Json& cameras = rig_node["cameras"];
    for (size_t c = 0; c < cameras.size(); ++c) {
      RigDescriptionCamera camera;
      bool ref_sensor = false;
      if (!ReadRigCamera(cameras[c], rig_where + " camera " + std::to_string(c),
                         &camera, &ref_sensor, error)) {
        return false;
      }
      if (ref_sensor) {
        if (rig.reference_camera >= 0) {
          *error = rig_where + " has more than one ref_sensor";
          return false;
        }
        rig.reference_camera = static_cast<int>(c);
      }
      rig.cameras.push_back(std::move(camera));
    }
    if (rig.reference_camera < 0) {
      *error = rig_where + " has no camera with \"ref_sensor\": true";
      return false;
    }
    rigs->push_back(std::move(rig));
  }
  return true;
}

bool WriteRigBundleAdjusterConfig(const std::string& path,
                                  const RigDescription& rig,
                                  std::string* error) {
  if (!CheckWritable(rig, error)) {
    return false;
  }
  const RigDescriptionCamera& reference = rig.cameras[rig.reference_camera];
  if (!reference.camera || !reference.cam_from_rig ||
      reference.camera->CameraId() == colmap::kInvalidCameraId) {
    *error = "the reference camera " + reference.name +
             " is not calibrated or has no camera id: COLMAP 3.8 "
             "rig_bundle_adjuster "
             "needs it";
    return false;
  }
  Json cameras = Json::array();
  for (const RigDescriptionCamera& camera : rig.cameras) {
    if (!camera.camera || !camera.cam_from_rig ||
        camera.camera->CameraId() == colmap::kInvalidCameraId) {
      continue;
    }
    Json node;
    node["camera_id"] = camera.camera->CameraId();
    node["image_prefix"] = camera.image_prefix;
    node["rel_qvec"] = QuaternionJson(camera.cam_from_rig->rotation);
    node["rel_tvec"] = VectorJson(camera.cam_from_rig->translation);
    cameras.push_back(node);
  }
  Json rig_node;
  rig_node["ref_camera_id"] = reference.camera->CameraId();
  rig_node["cameras"] = cameras;
  return WriteFileAtomically(
      path,
      Json::array({rig_node})
              .dump(2, ' ', false, Json::error_handler_t::replace) +
          "\n",
      error);
}

RigBundleAdjusterGrouping PredictRigBundleAdjusterGrouping(
    const RigDescription& rig, const colmap::Reconstruction& model) {
  RigBundleAdjusterGrouping grouping;
  std::vector<const RigDescriptionCamera*> cameras;
  std::set<colmap::camera_t> rig_camera_ids;
  for (const RigDescriptionCamera& camera : rig.cameras) {
    if (camera.camera && camera.cam_from_rig &&
        camera.camera->CameraId() != colmap::kInvalidCameraId) {
      cameras.push_back(&camera);
      rig_camera_ids.insert(camera.camera->CameraId());
    }
  }
  const RigDescriptionCamera& reference = rig.cameras[rig.reference_camera];
  if (!reference.camera) {
    return grouping;
  }
  const colmap::camera_t ref_camera_id = reference.camera->CameraId();

  // ReadCameraRigConfig: StringContains(name, prefix), then
  // StringGetAfter(name, prefix), which cuts after the last occurrence.
  std::map<std::string, std::vector<colmap::image_t>> snapshots;
  for (const colmap::image_t image_id : model.RegImageIds()) {
    const std::string& name = model.Image(image_id).Name();
    for (const RigDescriptionCamera* camera : cameras) {
      const size_t found = name.rfind(camera->image_prefix);
      if (found != std::string::npos) {
        snapshots[name.substr(found + camera->image_prefix.size())].push_back(
            image_id);
      }
    }
  }
  for (const auto& [key, image_ids] : snapshots) {
    bool has_ref = false;
    for (const colmap::image_t image_id : image_ids) {
      has_ref |= model.Image(image_id).CameraId() == ref_camera_id;
    }
    if (!has_ref) continue;
    ++grouping.num_snapshots;
    if (image_ids.size() > 1) ++grouping.num_multi_image_snapshots;
    const std::set<colmap::image_t> unique(image_ids.begin(), image_ids.end());
    for (const colmap::image_t image_id : image_ids) {
      const colmap::Image& image = model.Image(image_id);
      if (rig_camera_ids.count(image.CameraId()) == 0) {
        grouping.problems.push_back(
            "the image " + image.Name() + " (camera " +
            std::to_string(image.CameraId()) +
            ", not a rig camera) falls into the snapshot '" + key +
            "' because its name contains a rig camera prefix");
      }
    }
    if (unique.size() < image_ids.size()) {
      grouping.problems.push_back(
          "an image of the snapshot '" + key +
          "' contains two rig camera prefixes and is counted twice");
    }
    if (image_ids.size() > cameras.size()) {
      grouping.problems.push_back("the snapshot '" + key + "' has " +
                                  std::to_string(image_ids.size()) +
                                  " images but the rig only " +
                                  std::to_string(cameras.size()) + " cameras");
    }
  }
  return grouping;
}

}  // namespace rig_calibrator
