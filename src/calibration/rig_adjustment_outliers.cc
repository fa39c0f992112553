// Outlier pruning of the final bundle adjustment: see the pruning options in
// final_bundle_adjuster.h for the rules and their reasons.
#include <colmap/util/math.h>

#include <cmath>
#include <limits>

#include "src/calibration/rig_adjustment.h"

namespace rig_calibrator {

size_t RigAdjustment::RejectOutliers(bool prune_residuals) {
  if (options_.refine_points && !points_selected_) {
    SelectRefinedPoints();
  }
  // (slot, error) of the rig observations, then of the map observations of
  // the points being refined.
  const std::vector<MapObservationRef> map_observations =
      MapObservationsInProblem();
  const SlotErrors errors =
      EvaluateWithSlots(/*with_rig_observations=*/true, map_observations);
  const DepthRange depth_range = DepthRangeOf(errors);
  std::vector<double> max_error_px(cameras_.size() + map_cameras_.size(),
                                   std::numeric_limits<double>::infinity());
  if (prune_residuals) {
    max_error_px = MaxErrorPerSlot(errors);
  }
  const auto fits = [&](const std::pair<int, ObservationError>& error) {
    return depth_range.Contains(error.second.depth) &&
           error.second.residual.norm() <= max_error_px[error.first];
  };
  // Compacted in place, in their order: a new list would be 36 MB of fresh
  // memory at 10^6 observations (huge_page_allocator.h).
  const size_t num_rig = observations_.size();
  size_t num_kept = 0;
  for (size_t k = 0; k < num_rig; ++k) {
    if (fits(errors[k])) {
      if (num_kept != k) observations_[num_kept] = std::move(observations_[k]);
      ++num_kept;
    }
  }
  observations_.erase(observations_.begin() + num_kept, observations_.end());
  size_t num_removed = num_rig - num_kept;
  for (size_t k = 0; k < map_observations.size(); ++k) {
    if (!fits(errors[num_rig + k])) {
      map_rejected_[map_observations[k].image]
                   [map_observations[k].observation] = 1;
      ++num_map_rejected_;
      ++num_removed;
    }
  }
  if (num_removed > 0) selection_current_ = false;
  return num_removed;
}

size_t RigAdjustment::RejectMapOutliers() {
  const std::vector<MapObservationRef> map_observations =
      MapObservationsOfRefinedPoints();
  // The rig observations too, for the depth range only (the rig
  // observations' thresholds computed with it are not used here).
  const SlotErrors errors =
      EvaluateWithSlots(/*with_rig_observations=*/true, map_observations);
  const DepthRange depth_range = DepthRangeOf(errors);
  const std::vector<double> max_error_px = MaxErrorPerSlot(errors);
  const size_t num_rig = observations_.size();
  size_t num_rejected = 0;
  for (size_t k = 0; k < map_observations.size(); ++k) {
    const auto& [slot, error] = errors[num_rig + k];
    if (!(depth_range.Contains(error.depth) &&
          error.residual.norm() <= max_error_px[slot])) {
      map_rejected_[map_observations[k].image]
                   [map_observations[k].observation] = 1;
      ++num_rejected;
    }
  }
  num_map_rejected_ += num_rejected;
  if (num_rejected > 0) selection_current_ = false;
  return num_rejected;
}

RigAdjustment::DepthRange RigAdjustment::DepthRangeOf(
    const SlotErrors& errors) const {
  std::vector<double> depths;
  depths.reserve(observations_.size());
  for (size_t k = 0; k < observations_.size(); ++k) {
    if (errors[k].second.depth > 0) depths.push_back(errors[k].second.depth);
  }
  DepthRange range;
  if (!depths.empty()) {
    const double median = colmap::Median(depths);
    range.min = median / options_.max_depth_factor;
    range.max = median * options_.max_depth_factor;
  }
  return range;
}

// sigma = 1.4826 * MAD of the x and y residual components of the slot: the
// robust standard deviation of one component (1.4826 = 1 / Phi^-1(3/4) makes
// the MAD of a Gaussian its sigma).
std::vector<double> RigAdjustment::MaxErrorPerSlot(
    const SlotErrors& errors) const {
  const size_t num_slots = cameras_.size() + map_cameras_.size();
  std::vector<std::vector<double>> components(num_slots);
  for (const auto& [slot, error] : errors) {
    if (error.depth > 0) {
      components[slot].push_back(error.residual.x());
      components[slot].push_back(error.residual.y());
    }
  }
  std::vector<double> max_error_px(num_slots, options_.min_outlier_error_px);
  const int num_slots_int = static_cast<int>(num_slots);
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int slot = 0; slot < num_slots_int; ++slot) {
    if (components[slot].empty()) {
      continue;
    }
    const double median = colmap::Median(components[slot]);
    for (double& component : components[slot]) {
      component = std::abs(component - median);
    }
    const double sigma = 1.4826 * colmap::Median(components[slot]);
    max_error_px[slot] = std::max(options_.min_outlier_error_px,
                                  options_.outlier_sigma_factor * sigma);
  }
  return max_error_px;
}

}  // namespace rig_calibrator
