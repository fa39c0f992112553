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
#include "tests/e2e/calibration_output.h"

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

// Adds the differences between the images' poses and cam_from_rig *
// rig_from_world of `frame` to *composition and counts the frames of each
// image; false for an image that is not in the model or whose camera has
// no pose in the rig.
bool AddFrameCompositions(const colmap::Reconstruction& model,
                          const ColmapFrame& frame, const ColmapRig& rig,
                          PoseDifference* composition,
                          std::map<colmap::image_t, int>* frames_of_image) {
  bool ok = true;
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
    ++(*frames_of_image)[image.ImageId()];
    std::optional<Rigid3d> cam_from_rig;
    if (rig.ref_sensor.type == kSensorCamera &&
        rig.ref_sensor.id == data.sensor.id) {
      cam_from_rig = Rigid3d();
    }
    for (const ColmapRigSensor& sensor : rig.sensors) {
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
    composition->Max(ImagePose(image), *cam_from_rig * frame.rig_from_world);
  }
  return ok;
}

// Every registered image in exactly one frame, each pose cam_from_rig *
// rig_from_world of its frame; one multi-camera rig, returned (nullptr if
// none).
const ColmapRig* CheckFrames(const Output& output,
                             const ColmapRigsAndFrames& rigs_frames) {
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
    ok = AddFrameCompositions(model, frame, *rig->second, &composition,
                              &frames_of_image) &&
         ok;
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
  return calibrated_rig;
}

// The calibrated rig's sensors are the summary's cam_from_rig.
void CheckCalibratedRig(const Output& output, const ColmapRig& calibrated_rig) {
  const colmap::Reconstruction& model = output.model;
  PoseDifference rig_difference;
  int num_matched = 0;
  bool ok = true;
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
    if (calibrated_rig.ref_sensor.id == *camera_id) {
      cam_from_rig = Rigid3d();
      ok = ok && camera.name == output.summary.reference_camera;
    }
    for (const ColmapRigSensor& sensor : calibrated_rig.sensors) {
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

void CheckRigsAndFrames(const Output& output) {
  ColmapRigsAndFrames rigs_frames;
  std::string error;
  if (!ReadRigsAndFrames(output.folder, &rigs_frames, &error)) {
    Report("rigs/frames parse", error, false);
    return;
  }
  const ColmapRig* calibrated_rig = CheckFrames(output, rigs_frames);
  if (calibrated_rig != nullptr) CheckCalibratedRig(output, *calibrated_rig);
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

// The re-run has the reference run's cameras, intrinsics and cam_from_rig.
void CompareCamerasWithReference(const Output& output,
                                 const Output& reference) {
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
}

// Registered image poses, matched by name, relative to the scene size.
void ComparePosesWithReference(const Output& output, const Output& reference) {
  std::map<std::string, Rigid3d> reference_poses;
  for (const colmap::image_t image_id : reference.model.RegImageIds()) {
    const colmap::Image& image = reference.model.Image(image_id);
    reference_poses[image.Name()] = ImagePose(image);
  }
  PoseDifference pose_difference;
  double max_center_difference = 0;
  double scene_scale = 0;
  bool ok = output.model.NumRegImages() == reference_poses.size();
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
  if (argc == 3) {
    const Output reference = ReadOutput(argv[2]);
    CompareCamerasWithReference(output, reference);
    ComparePosesWithReference(output, reference);
  }
  std::cout << "[check] " << (NumFailedChecks() == 0 ? "all checks passed" : "")
            << (NumFailedChecks() > 0
                    ? std::to_string(NumFailedChecks()) + " check(s) FAILED"
                    : "")
            << std::endl;
  return NumFailedChecks() == 0 ? 0 : 1;
}
