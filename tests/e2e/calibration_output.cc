#include "tests/e2e/calibration_output.h"

#include <colmap/base/camera_models.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

namespace rig_calibrator {
namespace {

namespace fs = std::filesystem;

int num_failed_checks = 0;

}  // namespace

void Report(const std::string& name, const std::string& details, bool ok) {
  std::cout << "[check] " << name << ": " << details << ": "
            << (ok ? "ok" : "FAILED") << std::endl;
  if (!ok) ++num_failed_checks;
}

int NumFailedChecks() { return num_failed_checks; }

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

void PoseDifference::Max(const Rigid3d& a, const Rigid3d& b) {
  rotation_rad =
      std::max(rotation_rad, RotationDifferenceRad(a.rotation, b.rotation));
  translation = std::max(translation, (a.translation - b.translation).norm());
}

std::string PoseDifference::Text(const std::string& translation_unit) const {
  return "rotation " + Number(rotation_rad) + " rad, translation " +
         Number(translation) + translation_unit;
}

double RelativeDifference(const double a, const double b) {
  return std::abs(a - b) / std::max(1.0, std::abs(a));
}

Rigid3d ImagePose(const colmap::Image& image) {
  return Rigid3d::FromQvecTvec(image.Qvec(), image.Tvec());
}

namespace {

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

}  // namespace

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

Output ReadOutput(const std::string& folder) {
  if (!fs::is_directory(folder)) Die("no output folder " + folder);
  Output output;
  output.folder = folder;
  output.model = ReadModel(folder);
  output.summary = ReadSummary(folder + "/calibration_summary.json");
  return output;
}

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

}  // namespace rig_calibrator
