#include "colmap_ext/io/uncertainty_json.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "colmap_ext/io/json_number.h"

namespace rig_calibrator {
namespace {

using Json = nlohmann::ordered_json;

Json Vector(const Eigen::Vector3d& value) {
  return Json::array({JsonNumber(value.x()), JsonNumber(value.y()), JsonNumber(value.z())});
}

Json CameraJson(const CalibrationUncertainty& uncertainty,
                const CameraUncertainty& camera) {
  Json node;
  node["residual_scale_px"] = JsonNumber(uncertainty.residual_scale_px);
  node["determined"] = camera.determined;
  node["params_stddev"] = Json::array();
  for (const double stddev : camera.params_stddev) {
    node["params_stddev"].push_back(JsonNumber(stddev));
  }
  if (!camera.model_choice_stddev.empty()) {
    node["model_choice_stddev"] = Json::array();
    for (const double stddev : camera.model_choice_stddev) {
      node["model_choice_stddev"].push_back(JsonNumber(stddev));
    }
  }
  node["rotation_stddev_deg"] = JsonNumber(camera.rotation_stddev_deg);
  node["rotation_axis_stddev_deg"] = Vector(camera.rotation_axis_stddev_deg);
  node["translation_stddev"] = Vector(camera.translation_stddev);
  node["center_in_rig_stddev"] = Vector(camera.center_in_rig_stddev);
  node["between_framesets_factor"] =
      uncertainty.num_clusters > 0 ? JsonNumber(camera.between_framesets_factor)
                                   : Json(nullptr);
  const ProjectionUncertainty& projection = camera.projection;
  if (projection.stddev_px.empty()) {
    node["projection_stddev_px"] = nullptr;
    return node;
  }
  Json values = Json::array();
  for (const double value : projection.stddev_px)
    values.push_back(JsonNumber(value));
  node["projection_stddev_px"] = {
      {"median", JsonNumber(projection.median_px)},
      {"max", JsonNumber(projection.max_px)},
      {"max_at", Json::array({JsonNumber(projection.max_at.x()),
                              JsonNumber(projection.max_at.y())})},
      {"depth", JsonNumber(projection.depth)},
      {"grid",
       {{"cols", projection.cols},
        {"rows", projection.rows},
        {"values", values}}}};
  return node;
}

std::string Fixed(double value, int precision) {
  if (!std::isfinite(value)) return "undetermined";
  std::ostringstream text;
  text << std::fixed << std::setprecision(precision) << value;
  return text.str();
}

// "0.12" for one focal length, "0.12/0.13" for fx/fy (pixels).
std::string Joined(const std::vector<double>& stddevs,
                   const std::vector<size_t>& indices, int precision) {
  std::string text;
  for (const size_t k : indices) {
    if (!text.empty()) text += "/";
    text += k < stddevs.size() ? Fixed(stddevs[k], precision) : "?";
  }
  return text;
}

}  // namespace

void AddUncertaintyJson(const CalibrationUncertainty& uncertainty, Json* root) {
  Json& cameras = (*root)["cameras"];
  for (size_t c = 0; c < cameras.size(); ++c) {
    const bool has = uncertainty.computed && c < uncertainty.cameras.size() &&
                     uncertainty.cameras[c].computed;
    cameras[c]["uncertainty"] =
        has ? CameraJson(uncertainty, uncertainty.cameras[c]) : Json(nullptr);
  }
  (*root)["uncertainty_method"] = uncertainty.computed ? uncertainty.method
                                  : uncertainty.message.empty()
                                      ? std::string("not computed")
                                      : "not computed: " + uncertainty.message;
}

void AddUncertaintyComments(const CalibrationUncertainty& uncertainty,
                            RigDescription* rig) {
  if (!uncertainty.computed) return;
  for (size_t c = 0; c < rig->cameras.size() && c < uncertainty.cameras.size();
       ++c) {
    const CameraUncertainty& camera = uncertainty.cameras[c];
    RigDescriptionCamera& entry = rig->cameras[c];
    if (!camera.computed || !entry.camera) continue;
    std::ostringstream params;
    for (size_t k = 0; k < camera.params_stddev.size(); ++k) {
      params << (k == 0 ? "" : " ") << Fixed(camera.params_stddev[k], 6);
    }
    entry.comments.push_back(
        "1-sigma uncertainty (rig_calibrator, from the final adjustment; "
        "calibration_summary.json has all of it): COLMAP " +
        entry.camera->ModelName() + " params (" + entry.camera->ParamsInfo() +
        "): " + params.str());
    if (!camera.model_choice_stddev.empty()) {
      std::ostringstream spread;
      for (size_t k = 0; k < camera.model_choice_stddev.size(); ++k) {
        spread << (k == 0 ? "" : " ") << Fixed(camera.model_choice_stddev[k], 6);
      }
      entry.comments.push_back(
          "  at least the model choice's spread (another model fits as "
          "well; 0: the adjustment's is larger): " + spread.str());
    }
    entry.comments.push_back(
        "  cam_from_rig rotation " + Fixed(camera.rotation_stddev_deg, 5) +
        " deg, centre in the rig (" +
        Fixed(camera.center_in_rig_stddev.x(), 6) + ", " +
        Fixed(camera.center_in_rig_stddev.y(), 6) + ", " +
        Fixed(camera.center_in_rig_stddev.z(), 6) + ") map units");
    if (!camera.projection.stddev_px.empty()) {
      entry.comments.push_back(
          "  projection: median " + Fixed(camera.projection.median_px, 3) +
          " px, max " + Fixed(camera.projection.max_px, 3) + " px at (" +
          Fixed(camera.projection.max_at.x(), 0) + ", " +
          Fixed(camera.projection.max_at.y(), 0) + ") (COLMAP pixels)");
    }
  }
}

std::vector<std::string> UncertaintyLines(
    const std::vector<std::string>& camera_names,
    const std::vector<colmap::Camera>& cameras,
    const CalibrationUncertainty& uncertainty) {
  std::vector<std::string> lines;
  if (!uncertainty.computed) {
    lines.push_back("uncertainty not computed: " + uncertainty.message);
    return lines;
  }
  lines.push_back(
      "1-sigma uncertainty (residual scale " +
      Fixed(uncertainty.residual_scale_px, 3) + " px" +
      (uncertainty.free_gauge ? ", scale from the map's anchoring" : "") +
      "):");
  for (size_t c = 0; c < uncertainty.cameras.size() && c < cameras.size();
       ++c) {
    const CameraUncertainty& camera = uncertainty.cameras[c];
    if (!camera.computed) continue;
    const Eigen::Vector3d& center = camera.center_in_rig_stddev;
    std::ostringstream line;
    line << "  " << std::left << std::setw(8)
         << (c < camera_names.size() ? camera_names[c] : "") << std::right
         << " f " << Joined(camera.params_stddev, cameras[c].FocalLengthIdxs(), 3) << " pp "
         << Joined(camera.params_stddev, cameras[c].PrincipalPointIdxs(), 3)
         << " px, rotation " << Fixed(camera.rotation_stddev_deg, 4)
         << " deg, centre (" << Fixed(center.x(), 5) << ", "
         << Fixed(center.y(), 5) << ", " << Fixed(center.z(), 5) << ")";
    if (!camera.projection.stddev_px.empty()) {
      line << ", projection median " << Fixed(camera.projection.median_px, 3)
           << " max " << Fixed(camera.projection.max_px, 3) << " px at ("
           << Fixed(camera.projection.max_at.x(), 0) << ", "
           << Fixed(camera.projection.max_at.y(), 0) << ")";
    } else if (!camera.determined) {
      line << ", some parameters undetermined";
    }
    if (!camera.model_choice_stddev.empty()) {
      line << "; f and pp at least the model choice's spread ("
           << Joined(camera.model_choice_stddev, cameras[c].FocalLengthIdxs(),
                     3)
           << ", "
           << Joined(camera.model_choice_stddev,
                     cameras[c].PrincipalPointIdxs(), 3)
           << " px)";
    }
    if (camera.between_framesets_factor > kBetweenFramesetsNoteFactor) {
      line << "; framesets disagree " << Fixed(camera.between_framesets_factor, 1)
           << "x beyond the pixel noise";
    }
    lines.push_back(line.str());
  }
  return lines;
}

}  // namespace rig_calibrator
