// Helpers shared by the tests.
#pragma once

#include <colmap/base/camera.h>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace rig_calibrator {
namespace testing {

// A fresh, empty folder under the system's temporary folder, removed with
// everything in it when the object goes out of scope.
class ScopedTempDir {
 public:
  ScopedTempDir();
  ~ScopedTempDir();
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  const std::string& path() const { return path_; }
  // path() + "/" + name.
  std::string File(const std::string& name) const;

 private:
  std::string path_;
};

// A camera of the COLMAP model named `model` (e.g. "OPENCV_FISHEYE").
colmap::Camera MakeCamera(const std::string& model, int width, int height,
                          const std::vector<double>& params);

// The bytes of a file ("" if it cannot be read).
std::string ReadBytes(const std::string& path);

// The names of the entries of a folder.
std::set<std::string> ListFolder(const std::string& path);

// Every file below `folder` (path -> its bytes) and every folder below it
// (path -> "/"): two snapshots are equal iff nothing was added, removed or
// changed.
std::map<std::string, std::string> SnapshotFolder(const std::string& folder);

// The repository's root and the build tree, as configured by CMake.
std::string SourceDir();
std::string BinaryDir();

}  // namespace testing
}  // namespace rig_calibrator
