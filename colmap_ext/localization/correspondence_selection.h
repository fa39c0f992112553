// The deduplication of the localizer's 2D-3D matches: one map point per
// keypoint, one keypoint per map point.
#pragma once

#include <colmap/util/types.h>

#include <vector>

namespace rig_calibrator {

// One candidate 2D-3D match. `votes` counts the map images (or index hits)
// that support it; `angle` is its SIFT descriptor distance (radians).
struct CorrespondenceCandidate {
  colmap::point2D_t point2D_idx = colmap::kInvalidPoint2DIdx;
  colmap::point3D_t point3D_id = colmap::kInvalidPoint3DId;
  int votes = 1;
  float angle = 0;
};

// A one-to-one subset of the candidates: candidates of the same
// (keypoint, point) pair are merged (votes summed, smallest angle kept), then
// pairs are accepted greedily from the best (most votes, then smallest angle,
// then smallest keypoint and point ids) while neither their keypoint nor their
// point is taken.
std::vector<CorrespondenceCandidate> SelectOneToOneCorrespondences(
    std::vector<CorrespondenceCandidate> candidates);

}  // namespace rig_calibrator
