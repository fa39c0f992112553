#include "tests/fuzz/database_reads.h"

#include <algorithm>
#include <cstdlib>

#include "colmap_ext/io/database_reader.h"

namespace rig_calibrator {
namespace fuzz {
namespace {

void CheckFailureSaysWhy(bool ok, const std::string& error) {
  if (!ok && error.empty()) std::abort();
}

}  // namespace

void ReadWholeDatabase(const std::string& path) {
  DatabaseReader reader;
  std::string error;
  const bool opened = reader.Open(path, &error);
  CheckFailureSaysWhy(opened, error);
  if (!opened) return;
  const std::vector<DatabaseImage>& images = reader.Images();
  for (const DatabaseImage& image : images) {
    colmap::Camera camera;
    error.clear();
    CheckFailureSaysWhy(reader.ReadCamera(image.camera_id, &camera, &error),
                        error);
    colmap::FeatureKeypoints keypoints;
    error.clear();
    if (reader.ReadKeypoints(image.image_id, &keypoints, &error)) {
      if (static_cast<int>(keypoints.size()) !=
          reader.NumKeypoints(image.image_id)) {
        std::abort();
      }
    } else {
      CheckFailureSaysWhy(false, error);
    }
    colmap::FeatureDescriptors descriptors;
    error.clear();
    CheckFailureSaysWhy(
        reader.ReadDescriptors(image.image_id, &descriptors, &error), error);
    reader.NumDescriptors(image.image_id);
  }
  const size_t num_paired = std::min<size_t>(images.size(), 8);
  for (size_t i = 0; i < num_paired; ++i) {
    for (size_t j = 0; j < num_paired; ++j) {
      colmap::FeatureMatches matches;
      error.clear();
      CheckFailureSaysWhy(
          reader.ReadInlierMatches(images[i].image_id, images[j].image_id,
                                   &matches, &error),
          error);
    }
  }
  reader.NumVerifiedImagePairs();
}

}  // namespace fuzz
}  // namespace rig_calibrator
