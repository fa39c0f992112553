#include "colmap_ext/localization/point_descriptor_index.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rig_calibrator {
namespace {

constexpr float kHalfPi = static_cast<float>(M_PI / 2);

}  // namespace

float SiftDotToAngle(const int dot) {
  // COLMAP normalizes SIFT descriptors to length 512 before the uint8
  // conversion (feature/utils.cc), hence the 1 / 512^2.
  constexpr float kDotNorm = 1.0f / (512.0f * 512.0f);
  return std::acos(std::min(kDotNorm * dot, 1.0f));
}

float SiftDescriptorAngle(const uint8_t* descriptor1,
                          const uint8_t* descriptor2) {
  return SiftDotToAngle(SiftDescriptorDot(descriptor1, descriptor2));
}

std::vector<int> SelectRepresentativeDescriptors(
    const colmap::FeatureDescriptors& descriptors, const int max_count) {
  const int num_rows = static_cast<int>(descriptors.rows());
  std::vector<int> selected;
  if (num_rows <= max_count) {
    for (int row = 0; row < num_rows; ++row) selected.push_back(row);
    return selected;
  }
  if (max_count <= 0) return selected;

  const Eigen::RowVectorXf mean = descriptors.cast<float>().colwise().mean();
  int nearest_to_mean = 0;
  float best_squared_distance = std::numeric_limits<float>::max();
  for (int row = 0; row < num_rows; ++row) {
    const float squared_distance =
        (descriptors.row(row).cast<float>() - mean).squaredNorm();
    if (squared_distance < best_squared_distance) {
      best_squared_distance = squared_distance;
      nearest_to_mean = row;
    }
  }
  selected.push_back(nearest_to_mean);

  // Angle of every row to the nearest selected row.
  std::vector<float> angle_to_selected(num_rows);
  for (int row = 0; row < num_rows; ++row) {
    angle_to_selected[row] = SiftDescriptorAngle(
        descriptors.row(row).data(), descriptors.row(nearest_to_mean).data());
  }
  while (static_cast<int>(selected.size()) < max_count) {
    const int farthest = static_cast<int>(
        std::max_element(angle_to_selected.begin(), angle_to_selected.end()) -
        angle_to_selected.begin());
    if (angle_to_selected[farthest] <= 0) break;  // the rest are duplicates
    selected.push_back(farthest);
    for (int row = 0; row < num_rows; ++row) {
      angle_to_selected[row] =
          std::min(angle_to_selected[row],
                   SiftDescriptorAngle(descriptors.row(row).data(),
                                       descriptors.row(farthest).data()));
    }
  }
  return selected;
}

PointDescriptorIndex::PointDescriptorIndex() = default;
PointDescriptorIndex::~PointDescriptorIndex() = default;

void PointDescriptorIndex::SetDescriptors(
    colmap::FeatureDescriptors descriptors,
    std::vector<colmap::point3D_t> point3D_ids) {
  search_index_.reset();
  descriptors_ = std::move(descriptors);
  point3D_ids_ = std::move(point3D_ids);
  point_rows_.clear();
  max_rows_per_point_ = 0;
  for (int row = 0; row < static_cast<int>(point3D_ids_.size()); ++row) {
    auto [it, inserted] =
        point_rows_.emplace(point3D_ids_[row], std::make_pair(row, 0));
    ++it->second.second;
    max_rows_per_point_ = std::max(max_rows_per_point_, it->second.second);
  }
}

void PointDescriptorIndex::BuildSearchIndex(const Options& options) {
  options_ = options;
  search_index_.reset();
  if (descriptors_.rows() > 0) {
    search_index_ = std::make_unique<DescriptorKdForest>(
        descriptors_, options.num_trees, options.seed);
  }
}

void PointDescriptorIndex::Match(const colmap::FeatureDescriptors& query,
                                 const double max_ratio,
                                 const double max_distance,
                                 std::vector<PointMatch>* matches) const {
  matches->clear();
  if (search_index_ == nullptr || query.rows() == 0) return;

  const int k = std::min<int>(max_rows_per_point_ + 1, descriptors_.rows());
  DescriptorKdForest::IndexMatrix indices;
  search_index_->KnnSearch(query, k, options_.num_checks, &indices);

  for (int query_idx = 0; query_idx < query.rows(); ++query_idx) {
    const uint8_t* query_descriptor = query.row(query_idx).data();
    colmap::point3D_t best_point3D_id = colmap::kInvalidPoint3DId;
    float best_angle = kHalfPi;
    // The L2 order of the neighbours is not exactly the angle order (the
    // norms are only ~512), so the angles of all k are computed.
    std::vector<std::pair<float, colmap::point3D_t>> neighbours;
    for (int n = 0; n < k; ++n) {
      const int row = indices(query_idx, n);
      if (row < 0 || row >= descriptors_.rows()) continue;
      const float angle =
          SiftDescriptorAngle(query_descriptor, descriptors_.row(row).data());
      neighbours.emplace_back(angle, point3D_ids_[row]);
      if (best_point3D_id == colmap::kInvalidPoint3DId || angle < best_angle) {
        best_angle = angle;
        best_point3D_id = point3D_ids_[row];
      }
    }
    if (best_point3D_id == colmap::kInvalidPoint3DId) continue;
    float second_angle = kHalfPi;
    for (const auto& [angle, point3D_id] : neighbours) {
      if (point3D_id != best_point3D_id) {
        second_angle = std::min(second_angle, angle);
      }
    }
    // As COLMAP: reject on >= so that equal distances fail the ratio test.
    if (best_angle > max_distance || best_angle >= max_ratio * second_angle) {
      continue;
    }
    PointMatch match;
    match.query_idx = static_cast<colmap::point2D_t>(query_idx);
    match.point3D_id = best_point3D_id;
    match.angle = best_angle;
    matches->push_back(match);
  }
}

std::pair<int, int> PointDescriptorIndex::PointRows(
    const colmap::point3D_t point3D_id) const {
  const auto it = point_rows_.find(point3D_id);
  return it == point_rows_.end() ? std::make_pair(0, 0) : it->second;
}

float PointDescriptorIndex::AngleToPoint(
    const uint8_t* descriptor, const colmap::point3D_t point3D_id) const {
  const auto it = point_rows_.find(point3D_id);
  if (it == point_rows_.end()) return kHalfPi;
  float best_angle = kHalfPi;
  const auto [first_row, num_rows] = it->second;
  for (int row = first_row; row < first_row + num_rows; ++row) {
    best_angle =
        std::min(best_angle,
                 SiftDescriptorAngle(descriptor, descriptors_.row(row).data()));
  }
  return best_angle;
}

}  // namespace rig_calibrator
