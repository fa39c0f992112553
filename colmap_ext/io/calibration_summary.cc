#include "colmap_ext/io/calibration_summary.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/coverage_json.h"
#include "colmap_ext/io/json_number.h"
#include "colmap_ext/io/model_validity_json.h"
#include "colmap_ext/io/rig_description.h"
#include "colmap_ext/io/uncertainty_json.h"

namespace rig_calibrator {

CalibrationSummary SummarizeCalibration(
    const RigDataset& dataset, const RigCalibration& calibration,
    const std::vector<std::string>& image_prefixes) {
  CalibrationSummary summary;
  const RigDescription rig =
      DescribeCalibratedRig(dataset, calibration, image_prefixes);
  summary.reference_camera = dataset.cameras[dataset.reference_camera].name;
  summary.num_framesets = static_cast<int>(dataset.frameset_names.size());
  for (const std::optional<Rigid3d>& pose : calibration.rig_from_world) {
    summary.num_framesets_used += pose.has_value() ? 1 : 0;
  }

  // Sums of squared errors, pooled over the inliers of each camera's used
  // images: rms = sqrt(sum_i n_i rms_i^2 / sum_i n_i).
  std::vector<double> radial_sum(dataset.cameras.size(), 0);
  std::vector<double> full_sum(dataset.cameras.size(), 0);
  summary.cameras.resize(dataset.cameras.size());
  for (size_t c = 0; c < dataset.cameras.size(); ++c) {
    CameraSummary& camera = summary.cameras[c];
    camera.name = rig.cameras[c].name;
    camera.image_prefix = rig.cameras[c].image_prefix;
    camera.calibrated = calibration.camera_calibrated[c];
    camera.camera =
        camera.calibrated ? calibration.cameras[c] : dataset.cameras[c].camera;
    camera.cam_from_rig = rig.cameras[c].cam_from_rig;
  }
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const int c = dataset.images[i].camera_index;
    const ImageResult& result = calibration.images[i];
    CameraSummary& camera = summary.cameras[c];
    ++camera.num_images;
    camera.num_localized += result.localized ? 1 : 0;
    if (!result.used) continue;
    ++camera.num_used;
    camera.num_inliers += result.num_inliers;
    radial_sum[c] +=
        result.num_inliers * result.radial_rms_px * result.radial_rms_px;
    full_sum[c] += result.num_inliers * result.rms_px * result.rms_px;
  }
  for (size_t c = 0; c < summary.cameras.size(); ++c) {
    CameraSummary& camera = summary.cameras[c];
    if (camera.num_inliers > 0) {
      camera.radial_rms_px = std::sqrt(radial_sum[c] / camera.num_inliers);
      camera.rms_px = std::sqrt(full_sum[c] / camera.num_inliers);
    }
  }
  return summary;
}

namespace {

using Json = nlohmann::ordered_json;

// {"reference_camera", "num_image_poses", "rig_angular_speed_deg_s",
// "error" (null, or why the offsets were not measured), "cameras": [{"name",
// "offset_s", "offset_sigma_s" (null when infinite), "observable",
// "significant", "num_framesets_used", "diagnosis"}]}.
Json CaptureTimingJson(const CalibrationSummary& summary) {
  const CaptureTiming& timing = summary.capture_timing;
  Json node;
  node["reference_camera"] = summary.reference_camera;
  node["num_image_poses"] = timing.num_image_poses;
  node["rig_angular_speed_deg_s"] =
      JsonNumber(timing.rig_angular_speed_rad_s * 180.0 / M_PI);
  node["error"] = timing.error.empty() ? Json(nullptr) : Json(timing.error);
  node["cameras"] = Json::array();
  for (size_t c = 0; c < timing.offsets.size(); ++c) {
    const CameraTimeOffset& offset = timing.offsets[c];
    node["cameras"].push_back(
        {{"name", summary.cameras[c].name},
         {"offset_s", JsonNumber(offset.offset_s)},
         {"offset_sigma_s", std::isfinite(offset.offset_sigma_s)
                                ? JsonNumber(offset.offset_sigma_s)
                                : Json(nullptr)},
         {"observable", offset.observable},
         {"significant", static_cast<bool>(timing.significant[c])},
         {"num_framesets_used", offset.num_framesets_used},
         {"diagnosis", offset.diagnosis}});
  }
  return node;
}

// The camera's "timing" (CameraTiming): {"time_offset_s",
// "time_offset_sigma_s", "line_delay_s_per_row" and
// "line_delay_sigma_s_per_row" (both only when estimated), "source"}.
Json CameraTimingJson(const CameraTiming& timing) {
  Json node;
  node["time_offset_s"] = JsonNumber(timing.time_offset_s);
  node["time_offset_sigma_s"] = JsonNumber(timing.time_offset_sigma_s);
  if (timing.line_delay_s_per_row) {
    node["line_delay_s_per_row"] = JsonNumber(*timing.line_delay_s_per_row);
    node["line_delay_sigma_s_per_row"] =
        JsonNumber(timing.line_delay_sigma_s_per_row);
  }
  node["source"] = TimingSourceName(timing.source);
  return node;
}

// {"time_offsets_kept", "line_delays_kept", "rms_px", "rms_without_px",
// "message", "cameras": [{"name", "time_offset_s", "time_offset_sigma_s",
// "time_offset_estimated", "time_offset_significant", "line_delay_s",
// "line_delay_sigma_s", "line_delay_estimated", "line_delay_significant"}]}
// (a sigma null when not computed, JsonNumber; values of a kind not kept are the
// estimates that auto dropped).
Json CaptureTimeModelJson(const CalibrationSummary& summary) {
  const CaptureTimeModel& model = summary.capture_time_model;
  Json node;
  node["time_offsets_kept"] = model.time_offsets_kept;
  node["line_delays_kept"] = model.line_delays_kept;
  node["rms_px"] = JsonNumber(model.rms_px);
  node["rms_without_px"] = JsonNumber(model.rms_without_px);
  node["message"] = model.message;
  node["cameras"] = Json::array();
  for (size_t c = 0; c < model.cameras.size(); ++c) {
    const CameraCaptureTime& time = model.cameras[c];
    node["cameras"].push_back(
        {{"name", summary.cameras[c].name},
         {"time_offset_s", JsonNumber(time.time_offset_s)},
         {"time_offset_sigma_s", JsonNumber(time.time_offset_sigma_s)},
         {"time_offset_estimated", time.time_offset_estimated},
         {"time_offset_significant",
          static_cast<bool>(model.time_offset_significant[c])},
         {"line_delay_s", JsonNumber(time.line_delay_s)},
         {"line_delay_sigma_s", JsonNumber(time.line_delay_sigma_s)},
         {"line_delay_estimated", time.line_delay_estimated},
         {"line_delay_significant",
          static_cast<bool>(model.line_delay_significant[c])}});
  }
  return node;
}

bool WriteJson(const std::string& path, const Json& root, std::string* error) {
  return WriteFileAtomically(
      path, root.dump(2, ' ', false, Json::error_handler_t::replace) + "\n",
      error);
}

}  // namespace

void CompareWithKnownRig(const KnownRigPrior& prior,
                         CalibrationSummary* summary) {
  const int ref = prior.reference_camera;
  if (ref < 0 || ref >= static_cast<int>(summary->cameras.size()) ||
      !summary->cameras[ref].cam_from_rig) {
    return;
  }
  summary->known_rig_source = prior.source;
  summary->known_rig_reference_camera = summary->cameras[ref].name;
  // cam_from_ref = cam_from_rig * ref_from_rig^-1.
  const Rigid3d rig_from_ref = summary->cameras[ref].cam_from_rig->Inverse();
  for (size_t c = 0; c < summary->cameras.size(); ++c) {
    const CameraSummary& camera = summary->cameras[c];
    if (static_cast<int>(c) == ref || c >= prior.cam_from_ref.size() ||
        !prior.cam_from_ref[c] || !camera.cam_from_rig) {
      continue;
    }
    const Rigid3d calibrated = *camera.cam_from_rig * rig_from_ref;
    const Rigid3d& known = *prior.cam_from_ref[c];
    KnownPoseComparison comparison;
    comparison.camera = camera.name;
    comparison.rotation_error_deg =
        RotationDifferenceDeg(calibrated.rotation, known.rotation);
    comparison.translation_error =
        (calibrated.translation - known.translation).norm();
    comparison.known_translation_norm = known.translation.norm();
    summary->known_rig_comparison.push_back(comparison);
  }
}

bool WriteCalibrationSummaryJson(const std::string& path,
                                 const CalibrationSummary& summary,
                                 std::string* error) {
  Json root;
  root["method"] = summary.method;
  root["seed"] = summary.seed;
  root["units"] = summary.units;
  root["map_looks_metric"] = summary.map_looks_metric
                                 ? Json(*summary.map_looks_metric)
                                 : Json(nullptr);
  root["reference_camera"] = summary.reference_camera;
  root["num_framesets"] = summary.num_framesets;
  root["num_framesets_used"] = summary.num_framesets_used;
  Json cameras = Json::array();
  for (const CameraSummary& camera : summary.cameras) {
    Json node;
    node["name"] = camera.name;
    node["image_prefix"] = camera.image_prefix;
    node["calibrated"] = camera.calibrated;
    node["model"] = camera.camera.ModelName();
    node["width"] = camera.camera.Width();
    node["height"] = camera.camera.Height();
    node["params"] = Json::array();
    for (const double param : camera.camera.Params()) {
      node["params"].push_back(JsonNumber(param));
    }
    if (camera.cam_from_rig) {
      const Rigid3d& pose = *camera.cam_from_rig;
      node["cam_from_rig"] = {
          {"rotation_wxyz",
           {JsonNumber(pose.rotation.w()), JsonNumber(pose.rotation.x()),
            JsonNumber(pose.rotation.y()), JsonNumber(pose.rotation.z())}},
          {"translation",
           {JsonNumber(pose.translation.x()), JsonNumber(pose.translation.y()),
            JsonNumber(pose.translation.z())}}};
    } else {
      node["cam_from_rig"] = nullptr;
    }
    node["num_images"] = camera.num_images;
    node["num_localized"] = camera.num_localized;
    node["num_used"] = camera.num_used;
    node["num_inliers"] = camera.num_inliers;
    node["radial_rms_px"] = JsonNumber(camera.radial_rms_px);
    node["rms_px"] = JsonNumber(camera.rms_px);
    AddCameraModelJson(camera.camera_model, &node);
    AddCoverageJson(camera, &node);
    if (camera.timing) node["timing"] = CameraTimingJson(*camera.timing);
    cameras.push_back(node);
  }
  root["cameras"] = cameras;
  AddUncertaintyJson(summary.uncertainty, &root);
  if (summary.capture_timing.computed) {
    root["capture_time_offsets"] = CaptureTimingJson(summary);
  }
  if (std::any_of(summary.timestamp_offsets_s.begin(),
                  summary.timestamp_offsets_s.end(),
                  [](double offset) { return offset != 0; })) {
    // {"reference_camera", "offsets_s": {camera: its names minus the
    // reference camera's, seconds}}.
    Json offsets = Json::object();
    for (size_t c = 0; c < summary.cameras.size() &&
                       c < summary.timestamp_offsets_s.size();
         ++c) {
      offsets[summary.cameras[c].name] =
          JsonNumber(summary.timestamp_offsets_s[c]);
    }
    root["timestamp_offsets"] = {{"reference_camera", summary.reference_camera},
                                 {"offsets_s", offsets}};
  }
  if (summary.capture_time_model.computed) {
    root["capture_time_model"] = CaptureTimeModelJson(summary);
  }
  if (summary.known_rig_source.empty()) {
    root["known_rig"] = nullptr;
  } else {
    Json known = {{"source", summary.known_rig_source},
                  {"reference_camera", summary.known_rig_reference_camera},
                  {"cameras", Json::array()}};
    for (const KnownPoseComparison& comparison : summary.known_rig_comparison) {
      known["cameras"].push_back(
          {{"name", comparison.camera},
           {"rotation_error_deg", JsonNumber(comparison.rotation_error_deg)},
           {"translation_error", JsonNumber(comparison.translation_error)},
           {"known_translation_norm",
            JsonNumber(comparison.known_translation_norm)}});
    }
    root["known_rig"] = known;
  }
  if (summary.map_images) {
    const MapImagesSummary& map = *summary.map_images;
    root["map_images"] = {
        {"input_mean_error_px", JsonNumber(map.input_mean_error_px)},
        {"output_mean_error_px", JsonNumber(map.output_mean_error_px)},
        {"input_max_error_px", JsonNumber(map.input_max_error_px)},
        {"output_max_error_px", JsonNumber(map.output_max_error_px)},
        {"num_input_observations", map.num_input_observations},
        {"num_output_observations", map.num_output_observations},
        {"num_dropped_observations", map.num_dropped_observations}};
  }
  root["diagnostics"] = summary.diagnostics;
  return WriteJson(path, root, error);
}

bool WriteTimingsJson(const std::string& path,
                      const CalibrationSummary& summary, std::string* error) {
  Json timings = Json::object(), cpu = Json::object(),
       iterations = Json::object();
  for (const StageTiming& timing : summary.timings) {
    timings[timing.stage] = JsonNumber(timing.seconds);
    cpu[timing.stage] = JsonNumber(timing.cpu_seconds);
    if (timing.num_iterations > 0) {
      iterations[timing.stage] = timing.num_iterations;
    }
  }
  Json root;
  root["timings_s"] = timings;
  root["cpu_s"] = cpu;
  root["iterations"] = iterations;
  return WriteJson(path, root, error);
}

}  // namespace rig_calibrator
