#include "colmap_ext/io/rig_reference_io.h"

#include <boost/algorithm/string.hpp>
#include <boost/filesystem.hpp>

#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/model_writer.h"
#include "colmap_ext/io/rig_config_io.h"

namespace rig_calibrator {
namespace {

namespace fs = boost::filesystem;

bool ReadFirstRig(const std::string& path, RigDescription* rig,
                  std::string* error) {
  std::vector<RigDescription> rigs;
  if (!ReadRigConfigJson(path, &rigs, error)) return false;
  for (const RigDescription& candidate : rigs) {
    if (candidate.cameras.size() > 1) {
      *rig = candidate;
      return true;
    }
  }
  *error = path + " describes no rig with more than one camera";
  return false;
}

// rig_config.json has no image sizes; camchain.yaml does. Fills the sizes of
// `rig`'s cameras from the same-named cameras of `sized`.
void CopyImageSizes(const RigDescription& sized, RigDescription* rig) {
  for (RigDescriptionCamera& camera : rig->cameras) {
    if (!camera.camera) continue;
    for (const RigDescriptionCamera& other : sized.cameras) {
      if (other.name == camera.name && other.camera) {
        camera.camera->SetWidth(other.camera->Width());
        camera.camera->SetHeight(other.camera->Height());
      }
    }
  }
}

}  // namespace

bool ReadRigReference(const std::string& path, RigDescription* rig,
                      std::string* error) {
  const fs::path file(path);
  if (fs::is_directory(file)) {
    const fs::path config = file / kRigConfigFile;
    if (!fs::exists(config)) {
      *error = path + " has no " + std::string(kRigConfigFile) +
               ": it is not a rig_calibrator output folder";
      return false;
    }
    if (!ReadFirstRig(config.string(), rig, error)) return false;
    const fs::path camchain = file / kCamchainFile;
    if (fs::exists(camchain)) {
      RigDescription sized;
      if (ReadCamchainYaml(camchain.string(), &sized, error)) {
        CopyImageSizes(sized, rig);
      }
    }
    return true;
  }
  if (!fs::exists(file)) {
    *error = "the calibration file " + path + " does not exist";
    return false;
  }
  std::string extension = file.extension().string();
  boost::algorithm::to_lower(extension);
  if (extension == ".json") return ReadFirstRig(path, rig, error);
  if (extension == ".yaml" || extension == ".yml") {
    return ReadCamchainYaml(path, rig, error);
  }
  *error = path +
           " is neither a rig_config.json, a camchain.yaml nor a "
           "rig_calibrator output folder";
  return false;
}

}  // namespace rig_calibrator
