#include "colmap_ext/localization/radial_guided_matching.h"

#include <algorithm>
#include <cmath>

namespace rig_calibrator {

RadialLineIndex::RadialLineIndex(
    const LocalizationMap& map, const PointDescriptorIndex& index,
    const std::vector<colmap::point3D_t>& point3D_ids,
    const Rigid3d& cam_from_world) {
  const Eigen::Matrix3d rotation = cam_from_world.RotationMatrix();
  points_.reserve(point3D_ids.size());
  for (const colmap::point3D_t point3D_id : point3D_ids) {
    const auto point = map.points.find(point3D_id);
    if (point == map.points.end()) continue;
    const auto [first_row, num_rows] = index.PointRows(point3D_id);
    if (num_rows == 0) continue;
    const Eigen::Vector2d projection =
        (rotation * point->second.xyz + cam_from_world.translation).head<2>();
    const double norm = projection.norm();
    if (!(norm > 1e-9)) continue;
    LinePoint line_point;
    line_point.unit = projection / norm;
    line_point.direction = std::atan2(line_point.unit.y(), line_point.unit.x());
    line_point.point3D_id = point3D_id;
    line_point.first_row = first_row;
    line_point.num_rows = num_rows;
    points_.push_back(line_point);
  }
  std::sort(points_.begin(), points_.end(),
            [](const LinePoint& a, const LinePoint& b) {
              return a.direction < b.direction || (a.direction == b.direction &&
                                                   a.point3D_id < b.point3D_id);
            });
  constexpr int kDim = 128;
  int num_rows = 0;
  for (const LinePoint& point : points_) num_rows += point.num_rows;
  descriptors_.resize(static_cast<size_t>(num_rows) * kDim);
  int row = 0;
  for (LinePoint& point : points_) {
    for (int r = 0; r < point.num_rows; ++r) {
      std::copy_n(index.Descriptor(point.first_row + r), kDim,
                  descriptors_.data() + static_cast<size_t>(row + r) * kDim);
    }
    point.first_row = row;
    row += point.num_rows;
  }
}

void RadialLineIndex::Match(
    const colmap::FeatureDescriptors& descriptors,
    const std::vector<Eigen::Vector2d>& points2D_centered,
    const std::vector<int>& query_rows,
    const RadialGuidedMatchingOptions& options,
    std::vector<PointDescriptorIndex::PointMatch>* matches) const {
  if (points_.empty()) return;
  const double tolerance = options.max_line_distance_px;
  const auto by_direction = [](const LinePoint& point, const double direction) {
    return point.direction < direction;
  };
  for (const int row : query_rows) {
    const Eigen::Vector2d& u = points2D_centered[row];
    const double radius = u.norm();
    if (!(radius > tolerance)) continue;
    const double half_width = std::asin(tolerance / radius);
    const double direction = std::atan2(u.y(), u.x());
    const uint8_t* query = descriptors.row(row).data();

    int best_dot = -1;
    int second_dot = -1;
    colmap::point3D_t best_point3D_id = colmap::kInvalidPoint3DId;
    // The directions [from, to) of (-pi, pi], in order.
    const auto scan = [&](const double from, const double to) {
      for (auto it = std::lower_bound(points_.begin(), points_.end(), from,
                                      by_direction);
           it != points_.end() && it->direction < to; ++it) {
        const double along = u.dot(it->unit);
        const double across = u.x() * it->unit.y() - u.y() * it->unit.x();
        if (along <= 0 || std::abs(across) > tolerance) continue;
        int dot = 0;
        for (int r = it->first_row; r < it->first_row + it->num_rows; ++r) {
          dot = std::max(
              dot, SiftDescriptorDot(query, descriptors_.data() +
                                                static_cast<size_t>(r) * 128));
        }
        if (dot > best_dot) {
          second_dot = best_dot;
          best_dot = dot;
          best_point3D_id = it->point3D_id;
        } else if (dot > second_dot) {
          second_dot = dot;
        }
      }
    };
    const double from = direction - half_width;
    const double to = direction + half_width;
    // A window across +-pi is scanned in two parts, in direction order.
    if (from < -M_PI) {
      scan(from + 2 * M_PI, M_PI + 1);
      scan(-M_PI - 1, to);
    } else if (to > M_PI) {
      scan(from, M_PI + 1);
      scan(-M_PI - 1, to - 2 * M_PI);
    } else {
      scan(from, to);
    }
    if (best_point3D_id == colmap::kInvalidPoint3DId) continue;
    const float best_angle = SiftDotToAngle(best_dot);
    const float second_angle = second_dot < 0 ? static_cast<float>(M_PI / 2)
                                              : SiftDotToAngle(second_dot);
    // As PointDescriptorIndex::Match (COLMAP's rule, >= fails).
    if (best_angle > options.max_distance ||
        best_angle >= options.max_ratio * second_angle) {
      continue;
    }
    PointDescriptorIndex::PointMatch match;
    match.query_idx = static_cast<colmap::point2D_t>(row);
    match.point3D_id = best_point3D_id;
    match.angle = best_angle;
    matches->push_back(match);
  }
}

}  // namespace rig_calibrator
