#include "tests/testing.h"

#include <Eigen/Geometry>
#include <boost/filesystem.hpp>
#include <cmath>
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

Rigid3d SmoothWalkWorldFromBody(double t) {
  const double yaw = 0.3 * t + 0.35 * std::sin(2 * M_PI * 0.35 * t + 0.3);
  const double pitch = 0.15 * std::sin(2 * M_PI * 0.23 * t + 1.0);
  const double roll = 0.1 * std::sin(2 * M_PI * 0.41 * t);
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  return Rigid3d(rotation,
                 Eigen::Vector3d(1.3 * t,
                                 1.5 * std::sin(0.5 * t) + 0.2 * std::sin(2.1 * t),
                                 1.6 + 0.1 * std::sin(1.7 * t)));
}

}  // namespace testing
}  // namespace rig_calibrator
