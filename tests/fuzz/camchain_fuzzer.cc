// Fuzz target of the Kalibr camchain.yaml readers: ReadCamchainYaml and
// ReadRigReference on a *.yaml file.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/rig_reference_io.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  const std::string path = fuzz::WriteScratchFile("camchain.yaml", data, size);
  RigDescription rig;
  std::string error;
  if (!ReadCamchainYaml(path, &rig, &error) && error.empty()) std::abort();
  RigDescription reference;
  error.clear();
  if (!ReadRigReference(path, &reference, &error) && error.empty()) {
    std::abort();
  }
  return 0;
}
