#include "tests/testing.h"

#include <boost/filesystem.hpp>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace rig_calibrator {
namespace testing {

ScopedTempDir::ScopedTempDir() {
  namespace fs = boost::filesystem;
  const fs::path path = fs::temp_directory_path() /
                        fs::unique_path("rig_calibrator_test_%%%%-%%%%-%%%%");
  if (!fs::create_directories(path)) {
    throw std::runtime_error("cannot create " + path.string());
  }
  path_ = path.string();
}

ScopedTempDir::~ScopedTempDir() {
  boost::system::error_code error;
  boost::filesystem::remove_all(path_, error);
}

std::string ScopedTempDir::File(const std::string& name) const {
  return path_ + "/" + name;
}

colmap::Camera MakeCamera(const std::string& model, const int width,
                          const int height, const std::vector<double>& params) {
  colmap::Camera camera;
  camera.SetModelIdFromName(model);
  camera.SetWidth(width);
  camera.SetHeight(height);
  camera.SetParams(params);
  return camera;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file),
                     std::istreambuf_iterator<char>());
}

std::map<std::string, std::string> SnapshotFolder(const std::string& folder) {
  std::map<std::string, std::string> files;
  for (boost::filesystem::recursive_directory_iterator it(folder), end;
       it != end; ++it) {
    files[it->path().string()] = boost::filesystem::is_directory(it->path())
                                     ? "/"
                                     : ReadBytes(it->path().string());
  }
  return files;
}

std::set<std::string> ListFolder(const std::string& path) {
  std::set<std::string> names;
  for (boost::filesystem::directory_iterator it(path), end; it != end; ++it) {
    names.insert(it->path().filename().string());
  }
  return names;
}

std::string SourceDir() { return RIG_CALIBRATOR_SOURCE_DIR; }
std::string BinaryDir() { return RIG_CALIBRATOR_BINARY_DIR; }

}  // namespace testing
}  // namespace rig_calibrator
