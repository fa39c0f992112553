// Fuzz target of the rig_config.json readers: ReadRigConfigJson (every rig)
// and ReadRigReference (the rig reference a command is given, a *.json file).
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rig_reference_io.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  const std::string path =
      fuzz::WriteScratchFile("rig_config.json", data, size);
  std::vector<RigDescription> rigs;
  std::string error;
  if (!ReadRigConfigJson(path, &rigs, &error) && error.empty()) std::abort();
  RigDescription rig;
  error.clear();
  if (!ReadRigReference(path, &rig, &error) && error.empty()) std::abort();
  return 0;
}
