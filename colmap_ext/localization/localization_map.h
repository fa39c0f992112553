// The map as the localizer needs it (MapLocalizer): the registered map
// images under their database ids, the map point of every keypoint, the map
// points with their tracks, and an index of the tracks' descriptors.
#pragma once

#include <colmap/base/reconstruction.h>
#include <colmap/util/types.h>

#include <Eigen/Core>
#include <string>
#include <unordered_map>
#include <vector>

#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/localization/point_descriptor_index.h"

namespace rig_calibrator {

struct LocalizationMap {
  struct Point {
    Eigen::Vector3d xyz;
    std::vector<colmap::image_t> image_ids;  // database ids of its track
  };
  // Registered map images (database ids), sorted, and per image the map
  // point of every keypoint (kInvalidPoint3DId: none).
  std::vector<colmap::image_t> image_ids;
  std::unordered_map<colmap::image_t, std::vector<colmap::point3D_t>>
      image_point3D_ids;
  std::unordered_map<colmap::point3D_t, Point> points;
};

// Links the model's registered images to the database by name (model and
// database may number them differently). False with *error for a map
// without images or points, or a map image missing from the database or
// with another number of keypoints there than points2D in the model.
bool ReadLocalizationMap(const colmap::Reconstruction& map,
                         const DatabaseReader& database,
                         LocalizationMap* localization_map, std::string* error);

// Sets the descriptors of `index`: per map point, up to
// `max_descriptors_per_point` of its track's descriptors
// (SelectRepresentativeDescriptors, in parallel on `num_threads`). False
// with *error for a map inconsistent with its database or without any
// descriptor.
bool IndexTrackDescriptors(const LocalizationMap& localization_map,
                           const DatabaseReader& database,
                           int max_descriptors_per_point, int num_threads,
                           PointDescriptorIndex* index, std::string* error);

}  // namespace rig_calibrator
