// Outlier pruning of the final bundle adjustment: see the pruning options in
// final_bundle_adjuster.h for the rules and their reasons.
#include <colmap/util/math.h>

#include <cmath>
#include <limits>

#include "src/calibration/rig_adjustment.h"

namespace rig_calibrator {

size_t RigAdjustment::RejectOutliers(bool prune_residuals) {
  std::vector<ObservationError> errors(observations_.size());
  std::vector<double> depths;
  depths.reserve(observations_.size());
  for (size_t k = 0; k < observations_.size(); ++k) {
    errors[k] = Evaluate(observations_[k]);
    if (errors[k].depth > 0) {
      depths.push_back(errors[k].depth);
    }
  }
  const double max_depth =
      depths.empty() ? 0 : options_.max_depth_factor * colmap::Median(depths);
  std::vector<double> max_error_px(cameras_.size(),
                                   std::numeric_limits<double>::infinity());
  if (prune_residuals) {
    max_error_px = MaxErrorPerCamera(errors);
  }
  std::vector<Observation> kept;
  kept.reserve(observations_.size());
  for (size_t k = 0; k < observations_.size(); ++k) {
    if (errors[k].depth > 0 && errors[k].depth <= max_depth &&
        errors[k].residual.norm() <= max_error_px[CameraOf(observations_[k])]) {
      kept.push_back(observations_[k]);
    }
  }
  const size_t num_removed = observations_.size() - kept.size();
  observations_ = std::move(kept);
  return num_removed;
}

// sigma = 1.4826 * MAD of the x and y residual components of the camera: the
// robust standard deviation of one component (1.4826 = 1 / Phi^-1(3/4) makes
// the MAD of a Gaussian its sigma).
std::vector<double> RigAdjustment::MaxErrorPerCamera(
    const std::vector<ObservationError>& errors) const {
  std::vector<std::vector<double>> components(cameras_.size());
  for (size_t k = 0; k < observations_.size(); ++k) {
    if (errors[k].depth > 0) {
      const int camera = CameraOf(observations_[k]);
      components[camera].push_back(errors[k].residual.x());
      components[camera].push_back(errors[k].residual.y());
    }
  }
  std::vector<double> max_error_px(cameras_.size(),
                                   options_.min_outlier_error_px);
  for (size_t camera = 0; camera < cameras_.size(); ++camera) {
    if (components[camera].empty()) {
      continue;
    }
    const double median = colmap::Median(components[camera]);
    for (double& component : components[camera]) {
      component = std::abs(component - median);
    }
    const double sigma = 1.4826 * colmap::Median(components[camera]);
    max_error_px[camera] = std::max(options_.min_outlier_error_px,
                                    options_.outlier_sigma_factor * sigma);
  }
  return max_error_px;
}

}  // namespace rig_calibrator
