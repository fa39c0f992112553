#include "tests/fuzz/fuzz_files.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace rig_calibrator {
namespace fuzz {
namespace {

namespace fs = std::filesystem;

void RemoveScratchFolder() {
  std::error_code ignored;
  fs::remove_all(ScratchFolder(), ignored);
}

}  // namespace

const std::string& ScratchFolder() {
  // Never destroyed: RemoveScratchFolder runs at exit, after the destructors
  // of the statics constructed before it was registered.
  static const std::string* const folder = [] {
    std::string pattern =
        (fs::temp_directory_path() / "rig_calibrator_fuzz.XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) std::abort();
    return new std::string(pattern);
  }();
  static const bool registered = std::atexit(RemoveScratchFolder) == 0;
  (void)registered;
  return *folder;
}

std::string WriteScratchFile(const std::string& name, const uint8_t* data,
                             size_t size) {
  const std::string path = ScratchFolder() + "/" + name;
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(data),
             static_cast<std::streamsize>(size));
  if (!file) std::abort();
  return path;
}

void CopyFile(const std::string& from, const std::string& to) {
  std::ifstream source(from, std::ios::binary);
  std::ofstream target(to, std::ios::binary | std::ios::trunc);
  target << source.rdbuf();
  if (!source || !target) std::abort();
}

}  // namespace fuzz
}  // namespace rig_calibrator
