#include "colmap_ext/localization/correspondence_selection.h"

#include <algorithm>
#include <tuple>
#include <unordered_set>

namespace rig_calibrator {

std::vector<CorrespondenceCandidate> SelectOneToOneCorrespondences(
    std::vector<CorrespondenceCandidate> candidates) {
  std::sort(
      candidates.begin(), candidates.end(),
      [](const CorrespondenceCandidate& a, const CorrespondenceCandidate& b) {
        return std::tie(a.point2D_idx, a.point3D_id) <
               std::tie(b.point2D_idx, b.point3D_id);
      });
  std::vector<CorrespondenceCandidate> merged;
  for (const CorrespondenceCandidate& candidate : candidates) {
    if (!merged.empty() && merged.back().point2D_idx == candidate.point2D_idx &&
        merged.back().point3D_id == candidate.point3D_id) {
      merged.back().votes += candidate.votes;
      merged.back().angle = std::min(merged.back().angle, candidate.angle);
    } else {
      merged.push_back(candidate);
    }
  }
  std::sort(
      merged.begin(), merged.end(),
      [](const CorrespondenceCandidate& a, const CorrespondenceCandidate& b) {
        return std::make_tuple(-a.votes, a.angle, a.point2D_idx, a.point3D_id) <
               std::make_tuple(-b.votes, b.angle, b.point2D_idx, b.point3D_id);
      });
  std::unordered_set<colmap::point2D_t> taken_points2D;
  std::unordered_set<colmap::point3D_t> taken_points3D;
  std::vector<CorrespondenceCandidate> selected;
  for (const CorrespondenceCandidate& candidate : merged) {
    if (taken_points2D.count(candidate.point2D_idx) > 0 ||
        taken_points3D.count(candidate.point3D_id) > 0) {
      continue;
    }
    taken_points2D.insert(candidate.point2D_idx);
    taken_points3D.insert(candidate.point3D_id);
    selected.push_back(candidate);
  }
  return selected;
}

}  // namespace rig_calibrator
