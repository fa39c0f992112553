// Checks the output folder of a calibration, as a user's tools would read it:
//
//   check_calibration_outputs OUTPUT [REFERENCE_OUTPUT]
//
// * the COLMAP model (colmap::Reconstruction) holds the rig images, one
//   camera per calibrated rig camera, with the summary's model and parameters;
// * rigs/frames (COLMAP >= 3.12) parse, every registered image is in exactly
//   one frame, and every image's pose is cam_from_rig * rig_from_world of its
//   frame to 1e-9; the calibrated rig's cam_from_rig are the summary's;
// * rig_config.json and camchain.yaml agree with calibration_summary.json
//   (intrinsics as projections of a pixel grid, cam_from_rig as transforms).
// With REFERENCE_OUTPUT (e.g. the run from the database, OUTPUT the re-run
// from its correspondence file), also that both hold the same cameras, and
// intrinsics, cam_from_rig and rig image poses within 1e-6 (relative).
//
// Prints every check with its numbers; exit status 1 if any fails, 2 on
// usage or unreadable files.
#include <colmap/base/camera_models.h>
#include <colmap/base/reconstruction.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rigs_frames_io.h"
#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace {

namespace fs = std::filesystem;

// An output's image poses must be cam_from_rig * rig_from_world exactly up to
// floating-point rounding.
constexpr double kPoseCompositionTolerance = 1e-9;
// Numbers written by different writers of one run (text with 17 significant
// digits, or binary): rounding only.
constexpr double kSameRunTolerance = 1e-9;
// A projection through the Kalibr model of a camera that maps exactly.
constexpr double kExactKalibrTolerancePx = 1e-6;
// A re-run from the written correspondence file: the inputs are bit-identical
// (the file keeps every number exactly), so only the order of floating-point
// sums in multi-threaded Ceres differs.
constexpr double kRerunTolerance = 1e-6;

int g_num_failed = 0;

// Prints "[check] <name>: <details>: ok|FAILED" and counts failures.
void Report(const std::string& name, const std::string& details, bool ok) {
  std::cout << "[check] " << name << ": " << details << ": "
            << (ok ? "ok" : "FAILED") << std::endl;
  if (!ok) ++g_num_failed;
}

std::string Number(const double value) {
  std::ostringstream text;
  text.precision(3);
  text << value;
  return text.str();
}

[[noreturn]] void Die(const std::string& message) {
  std::cerr << "[check] ERROR: " << message << std::endl;
  std::exit(2);
}

// Rotation angle between two rotations (radians), accurate for tiny angles:
// 2 asin(|v|) of the vector part v of a^-1 b.
double RotationAngle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  const Eigen::Quaterniond difference = a.conjugate() * b;
  return 2 * std::asin(std::min(1.0, difference.vec().norm()));
}

struct PoseDifference {
  double rotation_rad = 0;
  double translation = 0;
  void Max(const Rigid3d& a, const Rigid3d& b) {
    rotation_rad =
        std::max(rotation_rad, RotationAngle(a.rotation, b.rotation));
    translation = std::max(translation, (a.translation - b.translation).norm());
  }
  std::string Text(const std::string& translation_unit = "") const {
    return "rotation " + Number(rotation_rad) + " rad, translation " +
           Number(translation) + translation_unit;
  }
};

double RelativeDifference(const double a, const double b) {
  return std::abs(a - b) / std::max(1.0, std::abs(a));
}

Rigid3d ImagePose(const colmap::Image& image) {
  return Rigid3d::FromQvecTvec(image.Qvec(), image.Tvec());
}

// One camera of calibration_summary.json.
struct SummaryCamera {
  std::string name;
  std::string image_prefix;
  bool calibrated = false;
  colmap::Camera camera;
  std::optional<Rigid3d> cam_from_rig;
  int num_used = 0;
};

struct Summary {
  std::string method;
  std::string reference_camera;
  int num_framesets_used = 0;
  std::vector<SummaryCamera> cameras;
};

Summary ReadSummary(const std::string& path) {
  std::ifstream file(path);
  if (!file) Die("cannot read " + path);
  Summary summary;
  try {
    const nlohmann::json json = nlohmann::json::parse(file);
    summary.method = json.at("method").get<std::string>();
    summary.reference_camera = json.at("reference_camera").get<std::string>();
    summary.num_framesets_used = json.at("num_framesets_used").get<int>();
    for (const nlohmann::json& node : json.at("cameras")) {
      SummaryCamera camera;
      camera.name = node.at("name").get<std::string>();
      camera.image_prefix = node.at("image_prefix").get<std::string>();
      camera.calibrated = node.at("calibrated").get<bool>();
      camera.num_used = node.at("num_used").get<int>();
      const std::string model = node.at("model").get<std::string>();
      if (!colmap::ExistsCameraModelWithName(model)) {
        Die(path + ": unknown camera model " + model);
      }
      camera.camera.SetModelIdFromName(model);
      camera.camera.SetWidth(node.at("width").get<size_t>());
      camera.camera.SetHeight(node.at("height").get<size_t>());
      camera.camera.SetParams(node.at("params").get<std::vector<double>>());
      if (!camera.camera.VerifyParams()) {
        Die(path + ": wrong number of parameters for camera " + camera.name);
      }
      const nlohmann::json& pose = node.at("cam_from_rig");
      if (!pose.is_null()) {
        const std::vector<double> q =
            pose.at("rotation_wxyz").get<std::vector<double>>();
        const std::vector<double> t =
            pose.at("translation").get<std::vector<double>>();
        if (q.size() != 4 || t.size() != 3) Die(path + ": malformed pose");
        camera.cam_from_rig =
            Rigid3d::FromQvecTvec(Eigen::Vector4d(q[0], q[1], q[2], q[3]),
                                  Eigen::Vector3d(t[0], t[1], t[2]));
      }
      summary.cameras.push_back(camera);
    }
  } catch (const std::exception& exception) {
    Die(path + ": " + exception.what());
  }
  return summary;
}

colmap::Reconstruction ReadModel(const std::string& folder) {
  colmap::Reconstruction model;
  if (fs::exists(folder + "/cameras.bin")) {
    model.ReadBinary(folder);
  } else if (fs::exists(folder + "/cameras.txt")) {
    model.ReadText(folder);
  } else {
    Die("no COLMAP model (cameras.bin or cameras.txt) in " + folder);
  }
  return model;
}

// The largest pixel distance between `a` and `b` over a grid of pixels:
// each pixel is lifted to a ray with `a` and projected with `b`.
double MaxProjectionDifferencePx(const colmap::Camera& a,
                                 const colmap::Camera& b) {
  constexpr int kGrid = 20;
  double max_difference = 0;
  for (int i = 0; i <= kGrid; ++i) {
    for (int j = 0; j <= kGrid; ++j) {
      const Eigen::Vector2d pixel(0.5 + (a.Width() - 1.0) * i / kGrid,
                                  0.5 + (a.Height() - 1.0) * j / kGrid);
      const Eigen::Vector2d ray = a.ImageToWorld(pixel);
      max_difference =
          std::max(max_difference, (b.WorldToImage(ray) - pixel).norm());
    }
  }
  return max_difference;
}

// Kalibr has an exact equivalent of these COLMAP models (camchain_io.h).
bool MapsExactlyToKalibr(const colmap::Camera& camera) {
  static const std::set<std::string> kExact = {"SIMPLE_PINHOLE",
                                               "PINHOLE",
                                               "SIMPLE_RADIAL",
                                               "RADIAL",
                                               "OPENCV",
                                               "OPENCV_FISHEYE",
                                               "FOV",
                                               "SIMPLE_RADIAL_FISHEYE",
                                               "RADIAL_FISHEYE"};
  return kExact.count(camera.ModelName()) > 0;
}

// The model's camera of the rig camera with `image_prefix`: the camera of
// its registered images (which must all share it).
std::optional<colmap::camera_t> ModelCameraOfPrefix(
    const colmap::Reconstruction& model, const std::string& image_prefix,
    int* num_images) {
  std::set<colmap::camera_t> camera_ids;
  *num_images = 0;
  for (const colmap::image_t image_id : model.RegImageIds()) {
    const colmap::Image& image = model.Image(image_id);
    if (image.Name().compare(0, image_prefix.size(), image_prefix) == 0) {
      camera_ids.insert(image.CameraId());
      ++*num_images;
    }
  }
  if (camera_ids.size() != 1) return std::nullopt;
  return *camera_ids.begin();
}

struct Output {
  std::string folder;
  colmap::Reconstruction model;
  Summary summary;
};

void CheckModel(const Output& output) {
  const Summary& summary = output.summary;
  const colmap::Reconstruction& model = output.model;
  int num_calibrated = 0;
  int num_rig_images = 0;
  int num_used = 0;
  double max_param_difference = 0;
  bool ok = true;
  std::set<colmap::camera_t> rig_camera_ids;
  for (const SummaryCamera& camera : summary.cameras) {
    if (!camera.calibrated) continue;
    ++num_calibrated;
    num_used += camera.num_used;
    int num_images = 0;
    const std::optional<colmap::camera_t> camera_id =
        ModelCameraOfPrefix(model, camera.image_prefix, &num_images);
    num_rig_images += num_images;
    if (!camera_id || !rig_camera_ids.insert(*camera_id).second) {
      std::cout << "[check]   camera " << camera.name
                << ": its images do not have one camera of their own"
                << std::endl;
      ok = false;
      continue;
    }
    const colmap::Camera& model_camera = model.Camera(*camera_id);
    if (model_camera.ModelId() != camera.camera.ModelId() ||
        model_camera.Width() != camera.camera.Width() ||
        model_camera.Height() != camera.camera.Height()) {
      std::cout << "[check]   camera " << camera.name << ": model "
                << model_camera.ModelName() << " " << model_camera.Width()
                << "x" << model_camera.Height() << ", summary "
                << camera.camera.ModelName() << std::endl;
      ok = false;
      continue;
    }
    for (size_t k = 0; k < model_camera.NumParams(); ++k) {
      max_param_difference = std::max(
          max_param_difference,
          RelativeDifference(camera.camera.Params(k), model_camera.Params(k)));
    }
  }
  ok = ok && num_calibrated >= 2 && num_rig_images == num_used &&
       max_param_difference <= kSameRunTolerance;
  Report("model cameras = summary",
         std::to_string(model.NumRegImages()) + " registered images (" +
             std::to_string(num_rig_images) +
             " rig images, summary: " + std::to_string(num_used) + " used), " +
             std::to_string(num_calibrated) +
             " calibrated cameras, max relative parameter difference " +
             Number(max_param_difference),
         ok);
}

void CheckRigsAndFrames(const Output& output) {
  ColmapRigsAndFrames rigs_frames;
  std::string error;
  if (!ReadRigsAndFrames(output.folder, &rigs_frames, &error)) {
    Report("rigs/frames parse", error, false);
    return;
  }
  const colmap::Reconstruction& model = output.model;
  std::map<uint32_t, const ColmapRig*> rigs;
  for (const ColmapRig& rig : rigs_frames.rigs) rigs[rig.rig_id] = &rig;

  PoseDifference composition;
  std::map<colmap::image_t, int> frames_of_image;
  bool ok = rigs.size() == rigs_frames.rigs.size();
  int num_rig_frames = 0;
  const ColmapRig* calibrated_rig = nullptr;
  for (const ColmapRig& rig : rigs_frames.rigs) {
    if (rig.sensors.empty()) continue;
    if (calibrated_rig != nullptr) ok = false;  // one multi-camera rig only
    calibrated_rig = &rig;
  }
  for (const ColmapFrame& frame : rigs_frames.frames) {
    const auto rig = rigs.find(frame.rig_id);
    if (rig == rigs.end()) {
      std::cout << "[check]   frame " << frame.frame_id << ": unknown rig "
                << frame.rig_id << std::endl;
      ok = false;
      continue;
    }
    num_rig_frames += rig->second == calibrated_rig ? 1 : 0;
    for (const ColmapFrameData& data : frame.data) {
      if (data.sensor.type != kSensorCamera ||
          !model.ExistsImage(static_cast<colmap::image_t>(data.data_id))) {
        std::cout << "[check]   frame " << frame.frame_id << ": image "
                  << data.data_id << " is not in the model" << std::endl;
        ok = false;
        continue;
      }
      const colmap::Image& image =
          model.Image(static_cast<colmap::image_t>(data.data_id));
      ++frames_of_image[image.ImageId()];
      std::optional<Rigid3d> cam_from_rig;
      if (rig->second->ref_sensor.type == kSensorCamera &&
          rig->second->ref_sensor.id == data.sensor.id) {
        cam_from_rig = Rigid3d();
      }
      for (const ColmapRigSensor& sensor : rig->second->sensors) {
        if (sensor.sensor.type == kSensorCamera &&
            sensor.sensor.id == data.sensor.id) {
          cam_from_rig = sensor.sensor_from_rig;
        }
      }
      if (!cam_from_rig || data.sensor.id != image.CameraId()) {
        std::cout << "[check]   image " << image.Name()
                  << ": its camera has no pose in rig " << frame.rig_id
                  << std::endl;
        ok = false;
        continue;
      }
      composition.Max(ImagePose(image), *cam_from_rig * frame.rig_from_world);
    }
  }
  for (const colmap::image_t image_id : model.RegImageIds()) {
    if (frames_of_image[image_id] != 1) {
      std::cout << "[check]   image " << model.Image(image_id).Name()
                << " is in " << frames_of_image[image_id] << " frames"
                << std::endl;
      ok = false;
    }
  }
  ok = ok && calibrated_rig != nullptr &&
       composition.rotation_rad <= kPoseCompositionTolerance &&
       composition.translation <= kPoseCompositionTolerance;
  Report("rigs/frames: cam_from_world = cam_from_rig * rig_from_world",
         std::to_string(rigs_frames.rigs.size()) + " rigs, " +
             std::to_string(rigs_frames.frames.size()) + " frames (" +
             std::to_string(num_rig_frames) +
             " of the calibrated rig, summary: " +
             std::to_string(output.summary.num_framesets_used) +
             " framesets used), " + std::to_string(frames_of_image.size()) +
             " images, max difference " + composition.Text() +
             " (<= " + Number(kPoseCompositionTolerance) + ")",
         ok);
  if (calibrated_rig == nullptr) return;

  // The calibrated rig's sensors are the summary's cam_from_rig.
  PoseDifference rig_difference;
  int num_matched = 0;
  ok = true;
  for (const SummaryCamera& camera : output.summary.cameras) {
    if (!camera.calibrated) continue;
    int num_images = 0;
    const std::optional<colmap::camera_t> camera_id =
        ModelCameraOfPrefix(model, camera.image_prefix, &num_images);
    if (!camera_id || !camera.cam_from_rig) {
      ok = false;
      continue;
    }
    std::optional<Rigid3d> cam_from_rig;
    if (calibrated_rig->ref_sensor.id == *camera_id) {
      cam_from_rig = Rigid3d();
      ok = ok && camera.name == output.summary.reference_camera;
    }
    for (const ColmapRigSensor& sensor : calibrated_rig->sensors) {
      if (sensor.sensor.id == *camera_id) cam_from_rig = sensor.sensor_from_rig;
    }
    if (!cam_from_rig) {
      std::cout << "[check]   camera " << camera.name
                << " is not in the calibrated rig" << std::endl;
      ok = false;
      continue;
    }
    rig_difference.Max(*cam_from_rig, *camera.cam_from_rig);
    ++num_matched;
  }
  ok = ok && rig_difference.rotation_rad <= kSameRunTolerance &&
       rig_difference.translation <= kSameRunTolerance;
  Report("rigs: cam_from_rig = summary",
         std::to_string(num_matched) + " cameras, max difference " +
             rig_difference.Text(),
         ok);
}

void CheckRigConfig(const Output& output) {
  std::vector<RigDescription> rigs;
  std::string error;
  if (!ReadRigConfigJson(output.folder + "/rig_config.json", &rigs, &error)) {
    Report("rig_config.json parse", error, false);
    return;
  }
  if (rigs.size() != 1) {
    Report("rig_config.json", std::to_string(rigs.size()) + " rigs", false);
    return;
  }
  const RigDescription& rig = rigs[0];
  PoseDifference pose_difference;
  double max_param_difference = 0;
  int num_matched = 0;
  bool ok = true;
  for (const SummaryCamera& camera : output.summary.cameras) {
    if (!camera.calibrated) continue;
    const auto it = std::find_if(rig.cameras.begin(), rig.cameras.end(),
                                 [&](const RigDescriptionCamera& c) {
                                   return c.image_prefix == camera.image_prefix;
                                 });
    if (it == rig.cameras.end() || !it->camera || !it->cam_from_rig ||
        it->camera->ModelId() != camera.camera.ModelId()) {
      std::cout << "[check]   rig_config.json: camera " << camera.name
                << " missing, without intrinsics or pose, or of another model"
                << std::endl;
      ok = false;
      continue;
    }
    if ((it - rig.cameras.begin() == rig.reference_camera) !=
        (camera.name == output.summary.reference_camera)) {
      std::cout << "[check]   rig_config.json: reference sensor differs"
                << std::endl;
      ok = false;
    }
    for (size_t k = 0; k < camera.camera.NumParams(); ++k) {
      max_param_difference = std::max(
          max_param_difference,
          RelativeDifference(camera.camera.Params(k), it->camera->Params(k)));
    }
    pose_difference.Max(*it->cam_from_rig, *camera.cam_from_rig);
    ++num_matched;
  }
  ok = ok && num_matched >= 2 && max_param_difference <= kSameRunTolerance &&
       pose_difference.rotation_rad <= kSameRunTolerance &&
       pose_difference.translation <= kSameRunTolerance;
  Report("rig_config.json = summary",
         std::to_string(num_matched) +
             " cameras, max relative parameter difference " +
             Number(max_param_difference) + ", cam_from_rig " +
             pose_difference.Text(),
         ok);
}

void CheckCamchain(const Output& output) {
  RigDescription rig;
  std::string error;
  if (!ReadCamchainYaml(output.folder + "/camchain.yaml", &rig, &error)) {
    Report("camchain.yaml parse", error, false);
    return;
  }
  // camchain.yaml lists the calibrated cameras in rig order, cam0 first, and
  // its rig frame is cam0's.
  std::vector<const SummaryCamera*> calibrated;
  for (const SummaryCamera& camera : output.summary.cameras) {
    if (camera.calibrated) calibrated.push_back(&camera);
  }
  if (rig.cameras.size() != calibrated.size() || calibrated.empty()) {
    Report("camchain.yaml = summary",
           std::to_string(rig.cameras.size()) + " cameras, summary " +
               std::to_string(calibrated.size()),
           false);
    return;
  }
  const Rigid3d first_from_rig = *calibrated[0]->cam_from_rig;
  double max_exact_px = 0;
  double max_fitted_px = 0;
  PoseDifference pose_difference;
  bool ok = true;
  for (size_t k = 0; k < calibrated.size(); ++k) {
    const SummaryCamera& camera = *calibrated[k];
    const RigDescriptionCamera& kalibr = rig.cameras[k];
    if (!kalibr.camera || !kalibr.cam_from_rig ||
        kalibr.camera->Width() != camera.camera.Width() ||
        kalibr.camera->Height() != camera.camera.Height()) {
      std::cout << "[check]   camchain.yaml: " << kalibr.name
                << " has no intrinsics, no pose or another image size"
                << std::endl;
      ok = false;
      continue;
    }
    const double difference =
        MaxProjectionDifferencePx(camera.camera, *kalibr.camera);
    double& max_px =
        MapsExactlyToKalibr(camera.camera) ? max_exact_px : max_fitted_px;
    max_px = std::max(max_px, difference);
    pose_difference.Max(*kalibr.cam_from_rig,
                        *camera.cam_from_rig * first_from_rig.Inverse());
  }
  ok = ok && max_exact_px <= kExactKalibrTolerancePx &&
       pose_difference.rotation_rad <= kSameRunTolerance &&
       pose_difference.translation <= kSameRunTolerance;
  Report("camchain.yaml = summary",
         std::to_string(calibrated.size()) +
             " cameras, max projection difference " + Number(max_exact_px) +
             " px (exact models, <= " + Number(kExactKalibrTolerancePx) + ")" +
             (max_fitted_px > 0
                  ? ", " + Number(max_fitted_px) + " px (fitted models)"
                  : "") +
             ", cam_from_cam0 " + pose_difference.Text(),
         ok);
}

// The re-run reproduces the reference run.
void CompareWithReference(const Output& output, const Output& reference) {
  bool ok =
      output.summary.cameras.size() == reference.summary.cameras.size() &&
      output.summary.reference_camera == reference.summary.reference_camera &&
      output.summary.method == reference.summary.method;
  double max_param_difference = 0;
  PoseDifference rig_difference;
  double rig_scale = 0;
  for (size_t c = 0; ok && c < output.summary.cameras.size(); ++c) {
    const SummaryCamera& a = reference.summary.cameras[c];
    const SummaryCamera& b = output.summary.cameras[c];
    if (a.name != b.name || a.calibrated != b.calibrated ||
        a.camera.ModelId() != b.camera.ModelId() || a.num_used != b.num_used) {
      std::cout << "[check]   camera " << a.name << " / " << b.name
                << ": name, model, calibrated or images used differ ("
                << a.num_used << " / " << b.num_used << " images)" << std::endl;
      ok = false;
      continue;
    }
    if (!a.calibrated) continue;
    for (size_t k = 0; k < a.camera.NumParams(); ++k) {
      max_param_difference =
          std::max(max_param_difference,
                   RelativeDifference(a.camera.Params(k), b.camera.Params(k)));
    }
    rig_difference.Max(*a.cam_from_rig, *b.cam_from_rig);
    rig_scale = std::max(rig_scale, a.cam_from_rig->translation.norm());
  }
  // Relative to the rig's size (absolute for a rig of co-located cameras).
  const double rig_translation =
      rig_difference.translation / (rig_scale > 0 ? rig_scale : 1.0);
  ok = ok && max_param_difference <= kRerunTolerance &&
       rig_difference.rotation_rad <= kRerunTolerance &&
       rig_translation <= kRerunTolerance;
  Report("re-run = reference: cameras",
         std::to_string(output.summary.cameras.size()) + " cameras, method " +
             output.summary.method + ", max relative intrinsics difference " +
             Number(max_param_difference) + ", cam_from_rig rotation " +
             Number(rig_difference.rotation_rad) + " rad, translation " +
             Number(rig_translation) +
             " of the rig size (<= " + Number(kRerunTolerance) + ")",
         ok);

  // Registered image poses, matched by name, relative to the scene size.
  std::map<std::string, Rigid3d> reference_poses;
  for (const colmap::image_t image_id : reference.model.RegImageIds()) {
    const colmap::Image& image = reference.model.Image(image_id);
    reference_poses[image.Name()] = ImagePose(image);
  }
  PoseDifference pose_difference;
  double max_center_difference = 0;
  double scene_scale = 0;
  ok = output.model.NumRegImages() == reference_poses.size();
  for (const colmap::image_t image_id : output.model.RegImageIds()) {
    const colmap::Image& image = output.model.Image(image_id);
    const auto it = reference_poses.find(image.Name());
    if (it == reference_poses.end()) {
      std::cout << "[check]   image " << image.Name()
                << " is not in the reference" << std::endl;
      ok = false;
      continue;
    }
    const Rigid3d pose = ImagePose(image);
    pose_difference.Max(pose, it->second);
    max_center_difference = std::max(
        max_center_difference, (pose.Center() - it->second.Center()).norm());
    scene_scale = std::max(scene_scale, it->second.Center().norm());
  }
  const double relative_center =
      max_center_difference / (scene_scale > 0 ? scene_scale : 1.0);
  ok = ok && pose_difference.rotation_rad <= kRerunTolerance &&
       relative_center <= kRerunTolerance;
  Report("re-run = reference: image poses",
         std::to_string(output.model.NumRegImages()) +
             " registered images, max rotation difference " +
             Number(pose_difference.rotation_rad) +
             " rad, max center difference " + Number(relative_center) +
             " of the scene size (" + Number(max_center_difference) +
             " map units)",
         ok);
}

Output ReadOutput(const std::string& folder) {
  if (!fs::is_directory(folder)) Die("no output folder " + folder);
  Output output;
  output.folder = folder;
  output.model = ReadModel(folder);
  output.summary = ReadSummary(folder + "/calibration_summary.json");
  return output;
}

}  // namespace
}  // namespace rig_calibrator

int main(int argc, char** argv) {
  using namespace rig_calibrator;
  if (argc < 2 || argc > 3) {
    std::cerr << "usage: " << argv[0] << " OUTPUT [REFERENCE_OUTPUT]"
              << std::endl;
    return 2;
  }
  const Output output = ReadOutput(argv[1]);
  std::cout << "[check] " << output.folder << ": method "
            << output.summary.method << ", " << output.summary.cameras.size()
            << " cameras, " << output.model.NumRegImages()
            << " registered images, " << output.model.NumPoints3D() << " points"
            << std::endl;
  CheckModel(output);
  CheckRigsAndFrames(output);
  CheckRigConfig(output);
  CheckCamchain(output);
  if (argc == 3) CompareWithReference(output, ReadOutput(argv[2]));
  std::cout << "[check] " << (g_num_failed == 0 ? "all checks passed" : "")
            << (g_num_failed > 0
                    ? std::to_string(g_num_failed) + " check(s) FAILED"
                    : "")
            << std::endl;
  return g_num_failed == 0 ? 0 : 1;
}
