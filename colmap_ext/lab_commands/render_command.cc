#include "colmap_ext/lab_commands/render_command.h"

#include <colmap/base/reconstruction.h>
#include <colmap/util/timer.h>

#include <boost/filesystem.hpp>
#include <boost/program_options.hpp>
#include <cmath>
#include <iostream>
#include <sstream>

#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/number_text.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rig_description.h"
#include "colmap_ext/lab_commands/synthetic_data_options.h"
#include "colmap_ext/lab_commands/time_model_json.h"

namespace rig_calibrator {
namespace {

namespace fs = boost::filesystem;

std::string PoseText(const Rigid3d& pose) {
  const Eigen::Vector4d q = pose.Qvec();
  std::string text;
  for (int k = 0; k < 4; ++k) text += " " + FormatDouble(q(k));
  for (int k = 0; k < 3; ++k) text += " " + FormatDouble(pose.translation(k));
  return text;
}

// "fx,fy,cx,cy": the form colmap's --ImageReader.camera_params takes.
std::string JoinedParams(const colmap::Camera& camera) {
  std::string text;
  for (const double param : camera.Params()) {
    text += (text.empty() ? "" : ",") + FormatDouble(param);
  }
  return text;
}

bool MakeFolder(const fs::path& path, std::string* error) {
  boost::system::error_code code;
  fs::create_directories(path, code);
  if (code) {
    *error = "cannot create " + path.string() + ": " + code.message();
    return false;
  }
  return true;
}

// A COLMAP text model of images with known poses and no points.
bool WritePoseModel(const fs::path& folder,
                    const std::vector<colmap::Camera>& cameras,
                    const std::vector<std::string>& names,
                    const std::vector<int>& camera_indices,
                    const std::vector<Rigid3d>& cam_from_world,
                    std::string* error) {
  if (!MakeFolder(folder, error)) return false;
  colmap::Reconstruction model;
  for (const colmap::Camera& camera : cameras) model.AddCamera(camera);
  for (size_t i = 0; i < names.size(); ++i) {
    colmap::Image image;
    image.SetImageId(static_cast<colmap::image_t>(i + 1));
    image.SetCameraId(cameras[camera_indices[i]].CameraId());
    image.SetName(names[i]);
    image.SetQvec(cam_from_world[i].Qvec());
    image.SetTvec(cam_from_world[i].translation);
    model.AddImage(image);
    model.RegisterImage(image.ImageId());
  }
  try {
    model.WriteText(folder.string());
  } catch (const std::exception& e) {
    *error = "cannot write the model " + folder.string() + ": " + e.what();
    return false;
  }
  return true;
}

// The map's true camera, image positions and poses.
bool WriteMapGroundTruth(const RenderedDatasetPlan& plan,
                         const fs::path& folder, std::string* error) {
  const colmap::Camera& map_camera = plan.map_camera;
  if (!WriteFileAtomically(
          (folder / "map_camera.txt").string(),
          "# MODEL WIDTH HEIGHT PARAMS (the map images' true camera)\n" +
              map_camera.ModelName() + " " +
              std::to_string(map_camera.Width()) + " " +
              std::to_string(map_camera.Height()) + " " +
              JoinedParams(map_camera) + "\n",
          error)) {
    return false;
  }
  std::string positions;
  for (size_t i = 0; i < plan.map_image_names.size(); ++i) {
    const Eigen::Vector3d center = plan.map_cam_from_world[i].Center();
    positions += plan.map_image_names[i] + " " + FormatDouble(center.x()) +
                 " " + FormatDouble(center.y()) + " " +
                 FormatDouble(center.z()) + "\n";
  }
  if (!WriteFileAtomically((folder / "map_image_positions.txt").string(),
                           positions, error)) {
    return false;
  }
  return WritePoseModel(folder / "map_model", {map_camera},
                        plan.map_image_names,
                        std::vector<int>(plan.map_image_names.size(), 0),
                        plan.map_cam_from_world, error);
}

// The rig: its poses per frameset, rig_config.json and the rig images' poses.
bool WriteRigGroundTruth(const RenderedDatasetPlan& plan,
                         const fs::path& folder, std::string* error) {
  const int num_cameras = static_cast<int>(plan.rig.cameras.size());
  std::vector<colmap::Camera> rig_cameras = plan.rig.cameras;
  std::vector<std::string> rig_names;
  std::vector<int> rig_camera_indices;
  std::vector<Rigid3d> rig_cam_from_world;
  std::string rig_poses =
      "# FRAMESET QW QX QY QZ TX TY TZ (rig_from_world; the rig frame is " +
      plan.rig.camera_names[0] + "'s)\n";
  RigDescription rig;
  for (int c = 0; c < num_cameras; ++c) {
    rig_cameras[c].SetCameraId(static_cast<colmap::camera_t>(c + 1));
    RigDescriptionCamera camera;
    camera.name = plan.rig.camera_names[c];
    camera.image_prefix = camera.name + "/";
    camera.camera = rig_cameras[c];
    camera.cam_from_rig = plan.rig.cam_from_rig[c];
    rig.cameras.push_back(camera);
  }
  for (size_t f = 0; f < plan.frameset_names.size(); ++f) {
    rig_poses +=
        plan.frameset_names[f] + PoseText(plan.rig.rig_from_world[f]) + "\n";
    for (int c = 0; c < num_cameras; ++c) {
      rig_names.push_back(plan.RigImageName(c, static_cast<int>(f)));
      rig_camera_indices.push_back(c);
      rig_cam_from_world.push_back(
          plan.HasTimeModel()
              ? plan.RigImageCapture(c, static_cast<int>(f)).CamFromWorldAt(
                    plan.rig.frameset_times_s[f] + plan.rig.time_offsets_s[c])
              : plan.rig.cam_from_rig[c] * plan.rig.rig_from_world[f]);
    }
  }
  return WriteFileAtomically((folder / "rig_from_world.txt").string(),
                             rig_poses, error) &&
         WriteRigConfigJson((folder / "rig_config.json").string(), rig,
                            error) &&
         WritePoseModel(folder / "rig_model", rig_cameras, rig_names,
                        rig_camera_indices, rig_cam_from_world, error);
}

bool WriteGroundTruth(const RenderedDatasetOptions& options,
                      const RenderedDatasetPlan& plan,
                      const RenderOptions& render_options,
                      const fs::path& folder, std::string* error) {
  if (!MakeFolder(folder, error) || !WriteMapGroundTruth(plan, folder, error) ||
      !WriteRigGroundTruth(plan, folder, error)) {
    return false;
  }
  const int num_cameras = static_cast<int>(plan.rig.cameras.size());
  // In the form of rig_calibrator's --RigCalibrator.camera_model.
  std::string camera_models;
  for (int c = 0; c < num_cameras; ++c) {
    camera_models += (c > 0 ? "," : "") + plan.rig.camera_names[c] + ":" +
                     plan.rig.cameras[c].ModelName();
  }
  std::ostringstream summary;
  summary << "scene " << SceneTypeName(options.scene) << "\n"
          << "preset " << RigPresetName(options.preset) << "\n"
          << "seed " << options.seed << "\n"
          << "num_map_images " << plan.map_image_names.size() << "\n"
          << "num_framesets " << plan.frameset_names.size() << "\n"
          << "num_rig_cameras " << num_cameras << "\n"
          << "camera_models " << camera_models << "\n"
          << "supersampling " << render_options.supersampling << "\n"
          << "noise_stddev " << render_options.noise_stddev << "\n"
          << "units meters, world z up\n";
  if (plan.HasTimeModel()) {
    summary << "frameset_rate_hz " << options.time_model.frameset_rate_hz
            << "\n"
            << "timestamp_tolerance_ns "
            << std::llround(plan.TimestampTolerance()) << "\n";
  }
  return WriteFileAtomically((folder / "dataset.txt").string(), summary.str(),
                             error) &&
         (!plan.HasTimeModel() ||
          WriteTimeModelJson((folder / "time_model.json").string(),
                             options.time_model, plan.frameset_names, plan.rig,
                             error));
}

bool RenderAndWrite(const TexturedScene& scene, const CameraRays& rays,
                    const std::vector<Rigid3d>& cam_from_world_per_row,
                    const RenderOptions& options, uint64_t noise_seed,
                    const fs::path& path, std::string* error) {
  const colmap::Bitmap bitmap =
      RenderImage(scene, rays, cam_from_world_per_row, options, noise_seed);
  if (bitmap.Width() == 0) {
    *error = "cannot render " + path.string();
    return false;
  }
  if (!bitmap.Write(path.string())) {
    *error = "cannot write " + path.string();
    return false;
  }
  return true;
}

}  // namespace

bool WriteRenderedDataset(const RenderedDatasetOptions& dataset_options,
                          const RenderedDatasetPlan& plan,
                          const RenderOptions& render_options,
                          const std::string& output_path, bool overwrite,
                          std::string* error) {
  if (!render_options.Check(error)) return false;
  OutputFolderOptions folder_options;
  folder_options.overwrite = overwrite;
  auto write = [&](const std::string& folder_path, std::string* error) {
    const fs::path folder(folder_path);
    colmap::Timer timer;
    timer.Start();
    // Noise seeds: distinct per image, derived from the dataset seed.
    const uint64_t seed_base =
        (static_cast<uint64_t>(dataset_options.seed) << 32);
    if (!MakeFolder(folder / "map_images", error)) return false;
    const CameraRays map_rays(plan.map_camera, render_options.supersampling);
    for (size_t i = 0; i < plan.map_image_names.size(); ++i) {
      const std::vector<Rigid3d> map_cam_from_world(
          map_rays.height(), plan.map_cam_from_world[i]);
      if (!RenderAndWrite(plan.scene, map_rays, map_cam_from_world,
                          render_options, seed_base + i,
                          folder / "map_images" / plan.map_image_names[i],
                          error)) {
        return false;
      }
    }
    const double map_seconds = timer.ElapsedSeconds();
    std::cout << "Rendered " << plan.map_image_names.size() << " map images in "
              << map_seconds << " s ("
              << map_seconds / plan.map_image_names.size() << " s per image)"
              << std::endl;

    timer.Restart();
    const int num_framesets = static_cast<int>(plan.frameset_names.size());
    for (size_t c = 0; c < plan.rig.cameras.size(); ++c) {
      const fs::path camera_folder =
          folder / "rig_images" / plan.rig.camera_names[c];
      if (!MakeFolder(camera_folder, error)) return false;
      const CameraRays rays(plan.rig.cameras[c], render_options.supersampling);
      if (rays.NumMaskedPixels() > 0) {
        std::cout << plan.rig.camera_names[c] << ": " << rays.NumMaskedPixels()
                  << " pixels outside the camera model's rays are black"
                  << std::endl;
      }
      for (int f = 0; f < num_framesets; ++f) {
        // Without a time model every row has the frameset's pose.
        const std::vector<Rigid3d> cam_from_world_per_row =
            plan.HasTimeModel()
                ? CamFromWorldPerRow(plan.RigImageCapture(c, f), rays.height())
                : std::vector<Rigid3d>(rays.height(),
                                       plan.rig.cam_from_rig[c] *
                                           plan.rig.rig_from_world[f]);
        const uint64_t noise_seed =
            seed_base + 0x80000000ull + c * num_framesets + f;
        if (!RenderAndWrite(
                plan.scene, rays, cam_from_world_per_row, render_options,
                noise_seed, folder / "rig_images" / plan.RigImageName(c, f),
                error)) {
          return false;
        }
      }
    }
    const double rig_seconds = timer.ElapsedSeconds();
    const size_t num_rig_images = plan.rig.cameras.size() * num_framesets;
    std::cout << "Rendered " << num_rig_images << " rig images in "
              << rig_seconds << " s (" << rig_seconds / num_rig_images
              << " s per image)" << std::endl;
    return WriteGroundTruth(dataset_options, plan, render_options,
                            folder / "ground_truth", error);
  };
  return WriteFolderAtomically(output_path, folder_options, write, error);
}

int RunRender(int argc, char** argv) {
  namespace po = boost::program_options;
  RenderedDatasetOptions dataset_options;
  RenderOptions render_options;
  std::string preset_name = "ring5";
  std::string scene_name = "room";
  std::string output_path;
  bool overwrite = false;
  po::options_description description =
      CommandOptions("rig_calibrator_lab render options");
  AddRequiredOption(
      &description, "output_path", &output_path,
      "folder to write (map_images/, rig_images/, ground_truth/)");
  AddOption(&description, "preset", &preset_name,
            "rig: ring5, fisheye_helmet5, car_surround4, stereo_pair");
  AddOption(&description, "scene", &scene_name,
            "scene: room, courtyard, street");
  AddOption(&description, "num_map_images", &dataset_options.num_map_images,
            "images of the mapping sequence");
  AddOption(&description, "num_framesets", &dataset_options.num_framesets,
            "framesets of the rig sequence");
  AddOption(&description, "seed", &dataset_options.seed,
            "seed of the textures, trajectories and noise");
  AddOption(&description, "map_width", &dataset_options.map_width,
            "map camera image width");
  AddOption(&description, "map_height", &dataset_options.map_height,
            "map camera image height");
  AddOption(&description, "map_focal_length", &dataset_options.map_focal_length,
            "map camera focal length in pixels (PINHOLE)");
  AddOption(&description, "rig_height", &dataset_options.rig_height,
            "height of the rig above the ground in meters (0: the scene's)");
  AddOption(&description, "supersampling", &render_options.supersampling,
            "samples per pixel along each axis at silhouettes and face "
            "boundaries");
  AddOption(&description, "noise_stddev", &render_options.noise_stddev,
            "Gaussian pixel noise in grey levels");
  AddOption(&description, "rgb", &render_options.as_rgb,
            "1: RGB images, 0: grey");
  TimeModelArguments time_model;
  AddTimeModelOptions(&description, &dataset_options.time_model, &time_model);
  AddOverwriteOption(&description, &overwrite);
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, description,
          "rig_calibrator_lab render: renders a rig dataset with exact ground "
          "truth (a mapping sequence and a rig calibration sequence)")) {
    return *exit_code;
  }
  if (!RigPresetFromName(preset_name, &dataset_options.preset)) {
    return PrintError("unknown --preset " + preset_name +
                      "; choose ring5, fisheye_helmet5, car_surround4 or "
                      "stereo_pair");
  }
  if (!SceneTypeFromName(scene_name, &dataset_options.scene)) {
    return PrintError("unknown --scene " + scene_name +
                      "; choose room, courtyard or street");
  }
  std::string error;
  RenderedDatasetPlan plan;
  if (!ApplyTimeModelArguments(time_model, &dataset_options.time_model,
                               &error) ||
      !PlanRenderedDataset(dataset_options, &plan, &error) ||
      !WriteRenderedDataset(dataset_options, plan, render_options, output_path,
                            overwrite, &error)) {
    return PrintError(error);
  }
  std::cout << "Wrote " << output_path << ": map_images/ ("
            << plan.map_image_names.size() << "), rig_images/ ("
            << plan.rig.cameras.size() << " cameras x "
            << plan.frameset_names.size() << " framesets), ground_truth/"
            << std::endl;
  if (plan.HasTimeModel()) {
    std::cout << "Time model in ground_truth/time_model.json; the rig images "
                 "are named by their capture times (ns): calibrate with "
                 "--RigCalibrator.timestamp_tolerance "
              << std::llround(plan.TimestampTolerance()) << std::endl;
  }
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
