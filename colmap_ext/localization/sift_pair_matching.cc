#include "colmap_ext/localization/sift_pair_matching.h"

#include <cmath>
#include <vector>

#include "colmap_ext/localization/point_descriptor_index.h"

namespace rig_calibrator {
namespace {

// For every row of `query`, the row of `database` that passes COLMAP's tests
// (FindBestMatchesOneWayFLANN): among the two neighbours, the nearest angle
// a1 <= max_distance and a1 < max_ratio * a2 (a2 = pi/2 without a second
// neighbour); -1 otherwise.
std::vector<int> MatchOneWay(const colmap::SiftMatchingOptions& options,
                             const colmap::FeatureDescriptors& query,
                             const colmap::FeatureDescriptors& database,
                             const DescriptorKdForest& database_forest) {
  std::vector<int> best_of(query.rows(), -1);
  if (query.rows() == 0 || database.rows() == 0) return best_of;
  const int k = std::min<int>(2, database.rows());
  DescriptorKdForest::IndexMatrix indices;
  database_forest.KnnSearch(query, k, kPairMatchingNumChecks, &indices);
  const float half_pi = static_cast<float>(M_PI / 2);
  for (int i = 0; i < query.rows(); ++i) {
    int best = -1;
    float best_angle = half_pi;
    float second_angle = half_pi;
    for (int n = 0; n < k; ++n) {
      const int row = indices(i, n);
      if (row < 0 || row >= database.rows()) continue;
      const float angle =
          SiftDescriptorAngle(query.row(i).data(), database.row(row).data());
      if (best < 0 || angle < best_angle) {
        second_angle = best < 0 ? second_angle : best_angle;
        best_angle = angle;
        best = row;
      } else if (angle < second_angle) {
        second_angle = angle;
      }
    }
    if (best < 0 || best_angle > options.max_distance ||
        best_angle >= options.max_ratio * second_angle) {
      continue;
    }
    best_of[i] = best;
  }
  return best_of;
}

}  // namespace

void MatchSiftDescriptors(const colmap::SiftMatchingOptions& options,
                          const colmap::FeatureDescriptors& descriptors1,
                          const DescriptorKdForest& forest1,
                          const colmap::FeatureDescriptors& descriptors2,
                          const DescriptorKdForest& forest2,
                          colmap::FeatureMatches* matches) {
  matches->clear();
  const std::vector<int> matches12 =
      MatchOneWay(options, descriptors1, descriptors2, forest2);
  std::vector<int> matches21;
  if (options.cross_check) {
    matches21 = MatchOneWay(options, descriptors2, descriptors1, forest1);
  }
  for (int i1 = 0; i1 < static_cast<int>(matches12.size()); ++i1) {
    const int i2 = matches12[i1];
    if (i2 < 0 || (options.cross_check && matches21[i2] != i1)) continue;
    matches->emplace_back(i1, i2);
  }
}

}  // namespace rig_calibrator
