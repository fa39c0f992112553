// Every read of DatabaseReader on a database, for the database fuzz targets.
#pragma once

#include <string>

namespace rig_calibrator {
namespace fuzz {

// Opens `path` and reads the cameras, keypoints and descriptors of every
// image and the inlier matches of every pair of its first 8 images; aborts if
// a failure comes without a message or a read contradicts the counts.
void ReadWholeDatabase(const std::string& path);

}  // namespace fuzz
}  // namespace rig_calibrator
