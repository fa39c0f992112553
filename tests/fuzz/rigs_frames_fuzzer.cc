// Fuzz target of the rigs/frames reader (ReadRigsAndFrames): the input's
// first byte chooses the file (rigs or frames, .bin or .txt) that the rest of
// the input replaces beside a valid other one (TemplateRigsAndFrames).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include "colmap_ext/io/rigs_frames_io.h"
#include "tests/fuzz/fuzz_files.h"
#include "tests/fuzz/fuzz_templates.h"

namespace {

constexpr const char* kFiles[] = {"rigs.bin", "frames.bin", "rigs.txt",
                                  "frames.txt"};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rig_calibrator;
  if (size == 0) return 0;
  const int file = data[0] % 4;
  const bool binary = file < 2;
  const std::string folder = fuzz::ScratchFolder() + (binary ? "/bin" : "/txt");
  std::filesystem::create_directories(folder);
  std::string error;
  // A fresh valid pair each time (the .bin pair is read when both exist).
  if (!WriteRigsAndFrames(folder, fuzz::TemplateRigsAndFrames(), binary,
                          &error)) {
    std::abort();
  }
  fuzz::WriteScratchFile(std::string(binary ? "bin/" : "txt/") + kFiles[file],
                         data + 1, size - 1);
  ColmapRigsAndFrames rigs_frames;
  error.clear();
  if (!ReadRigsAndFrames(folder, &rigs_frames, &error) && error.empty()) {
    std::abort();
  }
  return 0;
}
