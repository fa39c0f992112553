// Fuzz target of the correspondence file reader (ReadCorrespondenceFile): any
// input gives either correspondences or an error message, never a crash, a
// sanitizer report or an allocation beyond the file's size.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "colmap_ext/io/correspondence_io.h"
#include "tests/fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  const std::string path =
      fuzz::WriteScratchFile("correspondences.txt", data, size);
  std::vector<ImageCorrespondences> images;
  std::string error;
  if (!ReadCorrespondenceFile(path, &images, &error) && error.empty()) {
    std::abort();  // a failure must say why
  }
  return 0;
}
