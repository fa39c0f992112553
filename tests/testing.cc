#include "tests/testing.h"

#include <boost/filesystem.hpp>
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

std::string SourceDir() { return RIG_CALIBRATOR_SOURCE_DIR; }
std::string BinaryDir() { return RIG_CALIBRATOR_BINARY_DIR; }

}  // namespace testing
}  // namespace rig_calibrator
