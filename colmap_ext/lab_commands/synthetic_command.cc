// `rig_calibrator_lab synthetic`: writes a synthetic rig dataset (2D-3D
// correspondences) and its exact ground truth, to try the calibration or to
// feed benchmarks without images.
#include <boost/filesystem.hpp>
#include <iostream>

#include "colmap_ext/benchmarks/synthetic_map_model.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rig_description.h"
#include "colmap_ext/lab_commands/lab_commands.h"
#include "colmap_ext/lab_commands/synthetic_data_options.h"
#include "colmap_ext/lab_commands/time_model_json.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace {

RigDescription DescribeGroundTruth(const RigGroundTruth& truth) {
  RigDescription rig;
  for (size_t c = 0; c < truth.cameras.size(); ++c) {
    RigDescriptionCamera camera;
    camera.name = truth.camera_names[c];
    camera.image_prefix = camera.name + "/";
    camera.camera = truth.cameras[c];
    camera.cam_from_rig = truth.cam_from_rig[c];
    rig.cameras.push_back(camera);
  }
  return rig;
}

}  // namespace

int RunSynthetic(int argc, char** argv) {
  SyntheticRigOptions options;
  std::string preset = "ring5";
  std::string output_path;
  bool overwrite = false;
  int seed = 0;
  boost::program_options::options_description description =
      CommandOptions("rig_calibrator_lab synthetic options");
  AddRequiredOption(&description, "output_path", &output_path,
                    "output folder: correspondences.txt and ground_truth/");
  AddOption(&description, "preset", &preset,
            "ring5, fisheye_helmet5, car_surround4 or stereo_pair");
  AddOption(&description, "num_framesets", &options.num_framesets, "framesets");
  AddSyntheticDataOptions(&description, &options);
  AddOption(&description, "min_depth", &options.min_depth,
            "nearest map points (map units)");
  AddOption(&description, "max_depth", &options.max_depth,
            "farthest map points (map units)");
  AddOption(&description, "near_planar_ratio", &options.near_planar_ratio,
            "share of the correct correspondences on the ground plane");
  AddOption(&description, "stereo_num_pairs", &options.stereo_num_pairs,
            "stereo_pair: number of pairs, 0.25 m above each other");
  AddOption(&description, "stereo_alternate_facing",
            &options.stereo_alternate_facing,
            "stereo_pair: every second pair faces backward");
  AddOption(&description, "rotation_only", &options.rotation_only,
            "the rig only rotates about a fixed point");
  AddOption(&description, "map_scale", &options.map_scale,
            "map units per metre (1000: a map in millimetres)");
  AddOption(&description, "ring_num_cameras", &options.ring_num_cameras,
            "ring5 only: that many cameras on the ring (0: 5)");
  AddOption(&description, "image_height", &options.image_height,
            "every camera's image scaled to this many rows, intrinsics with "
            "it (0: the preset's sizes; 1080 for a 1080p rolling shutter)");
  AddOption(&description, "num_map_images", &options.num_map_images,
            "map images: > 0 writes the map as a COLMAP model (sparse/, "
            "with the map images' observations) and the correspondences "
            "with its point ids");
  AddOption(&description, "map_observations_per_image",
            &options.map_observations_per_image,
            "at most this many observations per map image (0: all visible)");
  AddOption(&description, "map_noise_px", &options.map_noise_px,
            "pixel noise of the map images' observations");
  AddOption(&description, "map_point_noise", &options.map_point_noise,
            "error of the map points (map units per coordinate)");
  TimeModelArguments time_model;
  AddTimeModelOptions(&description, &options, &time_model);
  AddOption(&description, "seed", &seed, "random seed");
  AddOverwriteOption(&description, &overwrite);
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, description,
          "rig_calibrator_lab synthetic: write a synthetic rig dataset with "
          "exact ground truth")) {
    return *exit_code;
  }
  if (!RigPresetFromName(preset, &options.preset)) {
    return PrintError("unknown preset " + preset +
                      "; use ring5, fisheye_helmet5, car_surround4 or "
                      "stereo_pair");
  }
  options.seed = static_cast<unsigned int>(seed);
  std::string error;
  if (!ApplyTimeModelArguments(time_model, &options, &error) ||
      !options.Check(&error)) {
    return PrintError(error);
  }
  const SyntheticRig rig = GenerateSyntheticRig(options);
  const RigDescription truth = DescribeGroundTruth(rig.truth);

  OutputFolderOptions folder_options;
  folder_options.overwrite = overwrite;
  const bool written = WriteFolderAtomically(
      output_path, folder_options,
      [&](const std::string& folder, std::string* write_error) {
        std::vector<std::string> notes;
        boost::filesystem::create_directories(folder + "/ground_truth");
        const bool data_written =
            options.num_map_images > 0
                ? WriteSyntheticMapModel(MakeSyntheticMapModel(rig), folder,
                                         /*binary=*/true, write_error)
                : WriteCorrespondenceFile(folder + "/correspondences.txt",
                                          DatasetCorrespondences(rig.dataset),
                                          write_error);
        return data_written &&
               WriteRigConfigJson(folder + "/ground_truth/rig_config.json",
                                  truth, write_error) &&
               WriteCamchainYaml(folder + "/ground_truth/camchain.yaml", truth,
                                 &notes, write_error) &&
               (options.frameset_rate_hz == 0 ||
                WriteTimeModelJson(folder + "/ground_truth/time_model.json",
                                   options, rig.dataset.frameset_names,
                                   rig.truth, write_error));
      },
      &error);
  if (!written) {
    return PrintError(error);
  }
  std::string models;
  for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
    models += (c ? "," : "") + rig.truth.camera_names[c] + ":" +
              rig.truth.cameras[c].ModelName();
  }
  std::cout << "Wrote " << rig.dataset.images.size() << " images of "
            << rig.truth.cameras.size() << " cameras in "
            << rig.dataset.frameset_names.size() << " framesets (" << preset
            << ") to " << output_path
            << (options.frameset_rate_hz > 0
                    ? " (time model in ground_truth/time_model.json)"
                    : "")
            << "\nCalibrate with:\n  rig_calibrator --correspondences_path "
            << output_path << "/correspondences.txt "
            << (options.num_map_images > 0
                    ? "--input_path " + output_path + "/sparse "
                    : std::string())
            << "--output_path OUT "
            << "--RigCalibrator.camera_model " << models
            << "\nEvaluate with:\n  rig_calibrator evaluate --reference_path "
            << output_path
            << "/ground_truth/camchain.yaml --calibration_path OUT"
            << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
