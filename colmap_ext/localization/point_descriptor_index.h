// A nearest-neighbour index from SIFT descriptors to map points: every map
// point contributes a few descriptors of its track (the observations in the
// map images); a FLANN kd-tree forest over all of them, built once per map,
// answers one query per feature of an image to localize. This replaces
// matching the image against each retrieved map image, where most of the
// localization's time went (retrieval mode still does that).
//
// Distances follow COLMAP's SIFT matcher (feature/sift.cc): SIFT descriptors
// are stored as uint8 with L2 norm ~512, and the distance of two descriptors
// is the angle acos(min(a.b / 512^2, 1)) in radians, so COLMAP's
// SiftMatching.max_ratio and SiftMatching.max_distance keep their meaning.
#pragma once

#include <colmap/feature/types.h>
#include <colmap/util/types.h>

#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include "colmap_ext/localization/descriptor_kd_forest.h"

namespace rig_calibrator {

// The dot product of two 128-byte SIFT descriptors (inline: the guided
// matcher's inner loop).
inline int SiftDescriptorDot(const uint8_t* descriptor1,
                             const uint8_t* descriptor2) {
  int dot = 0;
  for (int i = 0; i < 128; ++i) {
    dot += static_cast<int>(descriptor1[i]) * static_cast<int>(descriptor2[i]);
  }
  return dot;
}

// The angle of descriptors with dot product `dot`: acos(min(dot / 512^2, 1)).
float SiftDotToAngle(int dot);

// COLMAP's SIFT descriptor distance: the angle between the two 128-byte
// descriptors, acos(min(a.b / 512^2, 1)).
float SiftDescriptorAngle(const uint8_t* descriptor1,
                          const uint8_t* descriptor2);

// Up to `max_count` row indices of `descriptors` (the observations of one map
// point) that represent it: the row nearest to the mean descriptor, then
// repeatedly the row with the largest angle to the rows already chosen
// (farthest-point sampling), so that the viewpoints a long track spans stay
// covered. All rows if there are at most `max_count`.
std::vector<int> SelectRepresentativeDescriptors(
    const colmap::FeatureDescriptors& descriptors, int max_count);

class PointDescriptorIndex {
 public:
  struct Options {
    // FLANN kd-tree forest size and number of leaf checks per query. COLMAP's
    // CPU matcher uses 4 trees and 128 checks; 64 localizes twice as fast and
    // keeps 99.4 % of the 2D-3D correspondences (rendered ring5 demo, 100 rig
    // images of 4096 SIFT features: 190 504 -> 189 443, same calibration
    // accuracy; 32 checks keep 98.5 %).
    int num_trees = 4;
    int num_checks = 64;
    // Seed of the forest's construction (DescriptorKdForest): the same
    // descriptors, options and seed give the same matches.
    unsigned int seed = 0;
  };

  // A feature matched to a map point.
  struct PointMatch {
    colmap::point2D_t query_idx = colmap::kInvalidPoint2DIdx;
    colmap::point3D_t point3D_id = colmap::kInvalidPoint3DId;
    float angle = 0;  // SiftDescriptorAngle to the nearest point descriptor
  };

  PointDescriptorIndex();
  ~PointDescriptorIndex();
  PointDescriptorIndex(const PointDescriptorIndex&) = delete;
  PointDescriptorIndex& operator=(const PointDescriptorIndex&) = delete;

  // The descriptors (128 columns) and, per row, the map point it describes.
  // Rows of one point must be contiguous. Drops any search index built
  // before.
  void SetDescriptors(colmap::FeatureDescriptors descriptors,
                      std::vector<colmap::point3D_t> point3D_ids);

  // Builds the kd-tree forest (single-threaded, once per map; deterministic
  // for options.seed).
  void BuildSearchIndex(const Options& options);
  bool HasSearchIndex() const { return search_index_ != nullptr; }

  size_t NumDescriptors() const { return point3D_ids_.size(); }
  size_t NumPoints() const { return point_rows_.size(); }

  // For every query descriptor, the nearest map point if it passes the ratio
  // test against the nearest *other* map point: angle < max_ratio *
  // second_angle and angle <= max_distance (COLMAP's rule; the second
  // angle is pi/2 if no other point is found). The k = (most descriptors of
  // one point) + 1 nearest descriptors always include one of another point,
  // so the test is exact up to FLANN's approximation. Needs the search index;
  // safe to call from several threads at once.
  void Match(const colmap::FeatureDescriptors& query, double max_ratio,
             double max_distance, std::vector<PointMatch>* matches) const;

  // The rows [first, first + count) of the point's descriptors; {0, 0} if the
  // point is not in the index.
  std::pair<int, int> PointRows(colmap::point3D_t point3D_id) const;
  const uint8_t* Descriptor(int row) const {
    return descriptors_.row(row).data();
  }

  // Smallest SiftDescriptorAngle between `descriptor` and the descriptors of
  // the point; pi/2 (orthogonal) if the point is not in the index.
  float AngleToPoint(const uint8_t* descriptor,
                     colmap::point3D_t point3D_id) const;

 private:
  Options options_;
  colmap::FeatureDescriptors descriptors_;
  std::vector<colmap::point3D_t> point3D_ids_;
  // First row and number of rows of every point.
  std::unordered_map<colmap::point3D_t, std::pair<int, int>> point_rows_;
  int max_rows_per_point_ = 0;
  std::unique_ptr<DescriptorKdForest> search_index_;
};

}  // namespace rig_calibrator
