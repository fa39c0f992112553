#include "tests/fuzz/pipeline_case.h"

#include <cstdlib>
#include <filesystem>

#include "colmap_ext/benchmarks/synthetic_map_model.h"
#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rig_description.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace fuzz {
namespace {

SyntheticRig PipelineRig() {
  SyntheticRigOptions options;
  options.preset = RigPreset::kRing5;
  options.ring_num_cameras = 3;
  options.num_framesets = 6;
  options.points_per_image = 40;
  options.outlier_ratio = 0.1;
  options.missing_image_ratio = 0;
  options.num_map_images = 6;
  options.seed = 3;
  SyntheticRig rig = GenerateSyntheticRig(options);
  KeepCorrespondencesWithMapTracks(&rig);
  return rig;
}

void Check(const bool ok) {
  if (!ok) std::abort();
}

}  // namespace

const std::vector<std::string>& PipelineCaseFiles() {
  static const std::vector<std::string> files = {
      "txt/cameras.txt",     "txt/images.txt",      "txt/points3D.txt",
      "bin/cameras.bin",     "bin/images.bin",      "bin/points3D.bin",
      "correspondences.txt", "rig_config.json",     "camchain.yaml"};
  return files;
}

void WritePipelineCase(const std::string& folder) {
  const SyntheticRig rig = PipelineRig();
  const SyntheticMapModel model = MakeSyntheticMapModel(rig);
  std::string error;
  for (const bool binary : {false, true}) {
    const std::string subfolder = folder + (binary ? "/bin" : "/txt");
    std::filesystem::create_directories(subfolder + "/sparse");
    Check(WriteSyntheticMapModel(model, subfolder, binary, &error));
    for (const auto& entry :
         std::filesystem::directory_iterator(subfolder + "/sparse")) {
      std::filesystem::rename(entry.path(),
                              subfolder + "/" + entry.path().filename().string());
    }
    std::filesystem::remove(subfolder + "/sparse");
  }
  std::filesystem::rename(folder + "/txt/correspondences.txt",
                          folder + "/correspondences.txt");
  std::filesystem::remove(folder + "/bin/correspondences.txt");
  RigDescription truth;
  for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
    RigDescriptionCamera camera;
    camera.name = rig.truth.camera_names[c];
    camera.image_prefix = camera.name + "/";
    camera.camera = rig.truth.cameras[c];
    camera.cam_from_rig = rig.truth.cam_from_rig[c];
    truth.cameras.push_back(camera);
  }
  Check(WriteRigConfigJson(folder + "/rig_config.json", truth, &error));
  Check(WriteCamchainYaml(folder + "/camchain.yaml", truth, nullptr, &error));
}

std::vector<std::string> PipelineArguments(const std::string& folder,
                                           const std::string& selected,
                                           const std::string& output) {
  std::vector<std::string> arguments = {
      "--correspondences_path", folder + "/correspondences.txt",
      "--input_path",           folder + (selected[0] == 'b' ? "/bin" : "/txt"),
      "--output_path",          output,
      "--RigCalibrator.num_threads", "1"};
  const bool known = selected == "rig_config.json" || selected == "camchain.yaml";
  if (known) {
    arguments.insert(arguments.end(),
                     {"--RigCalibrator.method", "known",
                      "--RigCalibrator.intrinsics_path",
                      folder + "/" + selected});
  } else {
    arguments.insert(arguments.end(),
                     {"--RigCalibrator.camera_model", "OPENCV"});
  }
  return arguments;
}

}  // namespace fuzz
}  // namespace rig_calibrator
