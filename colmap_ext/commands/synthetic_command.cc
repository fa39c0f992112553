// `rig_calibrator synthetic`: writes a synthetic rig dataset (2D-3D
// correspondences) and its exact ground truth, to try the calibration or to
// feed benchmarks without images.
#include <boost/filesystem.hpp>
#include <boost/program_options.hpp>
#include <iostream>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rig_description.h"
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
  namespace po = boost::program_options;
  po::options_description description("rig_calibrator synthetic options");
  description.add_options()("help,h", "show this help")(
      "output_path", po::value(&output_path)->required(),
      "output folder: correspondences.txt and ground_truth/")(
      "preset", po::value(&preset)->default_value(preset),
      "ring5, fisheye_helmet5, car_surround4 or stereo_pair")(
      "num_framesets",
      po::value(&options.num_framesets)->default_value(options.num_framesets),
      "framesets")("points_per_image",
                   po::value(&options.points_per_image)
                       ->default_value(options.points_per_image),
                   "correspondences per image")(
      "noise_px", po::value(&options.noise_px)->default_value(options.noise_px),
      "pixel noise (standard deviation)")(
      "outlier_ratio",
      po::value(&options.outlier_ratio)->default_value(options.outlier_ratio),
      "share of wrong 2D-3D matches")(
      "missing_image_ratio",
      po::value(&options.missing_image_ratio)
          ->default_value(options.missing_image_ratio),
      "share of images dropped")(
      "min_depth",
      po::value(&options.min_depth)->default_value(options.min_depth),
      "nearest map points (map units)")(
      "max_depth",
      po::value(&options.max_depth)->default_value(options.max_depth),
      "farthest map points (map units)")(
      "seed", po::value(&seed)->default_value(seed), "random seed")(
      "overwrite", po::value(&overwrite)->default_value(false),
      "replace a non-empty output folder");
  int exit_code = EXIT_SUCCESS;
  if (!ParseCommandLine(argc, argv, description,
                        "rig_calibrator synthetic: write a synthetic rig "
                        "dataset with exact ground truth",
                        &exit_code)) {
    return exit_code;
  }
  if (!RigPresetFromName(preset, &options.preset)) {
    std::cerr << "ERROR: unknown preset " << preset
              << "; use ring5, fisheye_helmet5, car_surround4 or stereo_pair"
              << std::endl;
    return EXIT_FAILURE;
  }
  options.seed = static_cast<unsigned int>(seed);
  std::string error;
  if (!options.Check(&error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
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
        return WriteCorrespondenceFile(folder + "/correspondences.txt",
                                       DatasetCorrespondences(rig.dataset),
                                       write_error) &&
               WriteRigConfigJson(folder + "/ground_truth/rig_config.json",
                                  truth, write_error) &&
               WriteCamchainYaml(folder + "/ground_truth/camchain.yaml", truth,
                                 &notes, write_error);
      },
      &error);
  if (!written) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
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
            << "\nCalibrate with:\n  rig_calibrator --correspondences_path "
            << output_path << "/correspondences.txt --output_path OUT "
            << "--RigCalibrator.camera_model " << models
            << "\nEvaluate with:\n  rig_calibrator evaluate --reference_path "
            << output_path
            << "/ground_truth/camchain.yaml --calibration_path OUT"
            << std::endl;
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
