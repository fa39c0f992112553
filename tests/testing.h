// Helpers shared by the tests.
#pragma once

#include <colmap/base/camera.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

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

// world_from_body of a rig carried on a smooth walk at about 1.5 m/s (time t
// in seconds): yaw drifting at 0.3 rad/s plus a 0.35 Hz sway (peak turn rate
// about 65 deg/s, angular acceleration up to about 1.7 rad/s^2), pitch and
// roll nods, the body 1.6 m up. The time-offset and interpolation tests'
// trajectory.
Rigid3d SmoothWalkWorldFromBody(double t);

// The repository's root and the build tree, as configured by CMake.
std::string SourceDir();
std::string BinaryDir();

}  // namespace testing
}  // namespace rig_calibrator
