// The final bundle adjustment's time model (final_bundle_adjuster.h): the
// rig's motion around each frameset from the current rig poses, and the
// estimated offsets and line delays with their sigmas.
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "src/calibration/rig_adjustment.h"

namespace rig_calibrator {

void RigAdjustment::UpdateFramesetMotions() {
  std::vector<std::optional<Rigid3d>> poses(rig_from_world_.size());
  for (size_t f = 0; f < rig_from_world_.size(); ++f) {
    if (has_rig_pose_[f]) poses[f] = FromPoseParams(rig_from_world_[f]);
  }
  // Written in place: the costs point into frameset_motions_.
  std::vector<FramesetMotion> motions;
  std::string error;
  CHECK(ComputeFramesetMotions(dataset_.frameset_times_s, poses, &motions,
                               &error))
      << error << " (checked by AdjustRig)";
  std::copy(motions.begin(), motions.end(), frameset_motions_.begin());
}

// sigma_eff^2 = m/(m-p) mean(rho'(s)^2 s/2) / mean(rho'(s) + s rho''(s))^2
// over the rig observations, s = |r|^2, for the Cauchy loss of scale b:
// rho(s) = b^2 log(1 + s/b^2), rho' = 1/(1 + s/b^2), rho'' = -rho'^2 / b^2
// (Huber's M-estimate covariance scale, as calibration_uncertainty.h).
double RigAdjustment::EffectiveResidualVariance(int64_t num_parameters) const {
  const double b2 = options_.loss_scale_px * options_.loss_scale_px;
  double meat = 0, bread = 0;
  const ObservationErrors errors = EvaluateObservations();
  for (const ObservationError& error : errors) {
    const double s = error.residual.squaredNorm();
    const double d1 = 1 / (1 + s / b2);
    const double d2 = -d1 * d1 / b2;
    meat += d1 * d1 * s / 2;
    bread += d1 + s * d2;
  }
  const double n = static_cast<double>(errors.size());
  const double m = 2 * n;
  if (!(m > num_parameters) || !(bread > 0)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return m / (m - num_parameters) * (meat / n) / std::pow(bread / n, 2);
}

std::vector<CameraCaptureTime> RigAdjustment::CaptureTimes(
    std::string* sigma_error) {
  sigma_error->clear();
  // A camera without observations has its blocks outside the problem: not
  // estimated.
  std::vector<char> camera_used(time_offsets_.size(), 0);
  for (const Observation& observation : observations_) {
    camera_used[CameraOf(observation)] = 1;
  }
  std::vector<CameraCaptureTime> result(time_offsets_.size());
  std::vector<const double*> blocks;
  std::vector<double*> sigmas;
  for (size_t c = 0; c < result.size(); ++c) {
    CameraCaptureTime& time = result[c];
    time.time_offset_s = time_offsets_[c];
    time.line_delay_s = line_delays_[c];
    time.time_offset_estimated =
        options_.estimate_time_offsets && camera_used[c] &&
        static_cast<int>(c) != dataset_.reference_camera;
    time.line_delay_estimated = options_.estimate_line_delays && camera_used[c];
    if (time.time_offset_estimated) {
      blocks.push_back(&time_offsets_[c]);
      sigmas.push_back(&time.time_offset_sigma_s);
    }
    if (time.line_delay_estimated) {
      blocks.push_back(&line_delays_[c]);
      sigmas.push_back(&time.line_delay_sigma_s);
    }
  }
  if (blocks.empty()) return result;
  std::vector<double> variances;
  if (!solver_->Variances(blocks, &variances, sigma_error)) {
    for (double* sigma : sigmas) {
      *sigma = std::numeric_limits<double>::quiet_NaN();
    }
    return result;
  }
  const double scale = EffectiveResidualVariance(num_free_parameters_);
  if (!std::isfinite(scale)) {
    *sigma_error = "no redundancy for the residual scale";
  }
  for (size_t k = 0; k < sigmas.size(); ++k) {
    *sigmas[k] = std::sqrt(scale * variances[k]);
  }
  return result;
}

}  // namespace rig_calibrator
