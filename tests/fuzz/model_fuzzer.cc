// Fuzz target of the COLMAP model reader (ReadMap), every file type: the
// input's first byte chooses the file (cameras, images or points3D, .bin or
// .txt) that the rest of the input replaces in a valid model
// (TemplateModel), so that the reader gets past the other two.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include "colmap_ext/io/map_reader.h"
#include "tests/fuzz/fuzz_files.h"
#include "tests/fuzz/fuzz_templates.h"

namespace {

constexpr const char* kFiles[] = {"cameras.bin", "images.bin", "points3D.bin",
                                  "cameras.txt", "images.txt", "points3D.txt"};

// The scratch folders bin/ and txt/, holding the valid model.
std::string ModelFolder(bool binary) {
  using namespace rig_calibrator;
  static const bool written = [] {
    const colmap::Reconstruction model = fuzz::TemplateModel();
    for (const char* format : {"bin", "txt"}) {
      const std::string folder = fuzz::ScratchFolder() + "/" + format;
      std::filesystem::create_directories(folder);
      std::filesystem::create_directories(folder + "_valid");
      if (format[0] == 'b') {
        model.WriteBinary(folder);
        model.WriteBinary(folder + "_valid");
      } else {
        model.WriteText(folder);
        model.WriteText(folder + "_valid");
      }
    }
    return true;
  }();
  (void)written;
  return rig_calibrator::fuzz::ScratchFolder() + (binary ? "/bin" : "/txt");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  if (size == 0) return 0;
  const int file = data[0] % 6;
  const std::string folder = ModelFolder(file < 3);
  fuzz::WriteScratchFile(std::string(file < 3 ? "bin/" : "txt/") + kFiles[file],
                         data + 1, size - 1);
  colmap::Reconstruction map;
  std::string error;
  if (!ReadMap(folder, &map, &error) && error.empty()) std::abort();
  fuzz::CopyFile(folder + "_valid/" + kFiles[file], folder + "/" + kFiles[file]);
  return 0;
}
