// Guided 2D-3D matching along radial lines: once the 1D radial pose of an
// image is known (RANSAC on its strongest features, MapLocalizer), a feature
// at image point u (relative to the distortion center) can only be the
// projection of a map point X whose radial projection p = (R X + t)_xy points
// the same way: under any radial distortion u = lambda p with lambda > 0
// (paper §3.1). Each remaining feature is therefore compared with the map
// points whose radial line passes within `max_line_distance_px` of u, on the
// same side of the center, instead of being searched among all map points:
//
//   |u x p| / |p| <= max_line_distance_px   and   u . p > 0.
//
// The map points are sorted by the direction of p once per image, so that
// the candidates of u are a contiguous range of directions,
// atan2(u) +- asin(max_line_distance_px / |u|). The rule that accepts a match
// is the index's (PointDescriptorIndex::Match): nearest point by
// SiftDescriptorAngle over its descriptors, angle <= max_distance and angle <
// max_ratio * (angle of the second-nearest candidate point, pi/2 if none);
// only the set of points it compares with differs.
#pragma once

#include <colmap/feature/types.h>
#include <colmap/util/types.h>

#include <Eigen/Core>
#include <vector>

#include "colmap_ext/localization/localization_map.h"
#include "colmap_ext/localization/point_descriptor_index.h"
#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

struct RadialGuidedMatchingOptions {
  // Largest distance, pixels, between a feature and the radial line of a
  // candidate point. It must cover the pose's radial error and the offset of
  // the true principal point from the assumed one (the image center).
  double max_line_distance_px = 12;
  double max_ratio = 0.8;
  double max_distance = 0.7;  // radians
};

// The candidate map points of one image, sorted by the direction of their
// radial projection under `cam_from_world`.
class RadialLineIndex {
 public:
  // `point3D_ids`: points of `map`; those without descriptors in `index`
  // and those projecting within 1e-9 of the center (on the optical axis) are
  // left out.
  RadialLineIndex(const LocalizationMap& map, const PointDescriptorIndex& index,
                  const std::vector<colmap::point3D_t>& point3D_ids,
                  const Rigid3d& cam_from_world);

  size_t NumPoints() const { return points_.size(); }

  // Matches the `query_rows` of `descriptors`, whose image points relative to
  // the distortion center are `points2D_centered` (one per row of
  // `descriptors`). Features within max_line_distance_px of the center are
  // skipped (every direction passes there). Appends to *matches, in the order
  // of `query_rows`.
  void Match(const colmap::FeatureDescriptors& descriptors,
             const std::vector<Eigen::Vector2d>& points2D_centered,
             const std::vector<int>& query_rows,
             const RadialGuidedMatchingOptions& options,
             std::vector<PointDescriptorIndex::PointMatch>* matches) const;

 private:
  struct LinePoint {
    double direction = 0;  // atan2 of the unit radial projection, (-pi, pi]
    Eigen::Vector2d unit = Eigen::Vector2d::Zero();
    colmap::point3D_t point3D_id = colmap::kInvalidPoint3DId;
    int first_row = 0;  // of its descriptors in descriptors_
    int num_rows = 0;
  };
  std::vector<LinePoint> points_;
  // The points' descriptors copied from the index in the order of points_,
  // so that a window of directions reads contiguous memory (the index's rows
  // of neighbouring directions are scattered over the whole map).
  std::vector<uint8_t> descriptors_;  // by direction, then point3D_id
};

}  // namespace rig_calibrator
