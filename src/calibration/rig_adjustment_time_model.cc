// The final bundle adjustment's time model (final_bundle_adjuster.h): the
// rig's motion around each frameset from the current rig poses, the priors
// of the estimated velocities and accelerations, and the estimated offsets
// and line delays.
#include <glog/logging.h>

#include <algorithm>

#include "src/calibration/rig_adjustment.h"
#include "src/geometry/timed_rig_reprojection_cost.h"
#include "src/geometry/translation_prior_cost.h"

namespace rig_calibrator {

// The frameset motions from the current poses; where the alternation
// between the motions and the poses would grow the poses' errors at the
// images' instants (the current offsets, line delays at the middle row), a
// frameset's motion leaves its own pose out (FramesetsWithoutOwnPose,
// frameset_motion.h).
void RigAdjustment::UpdateFramesetMotions() {
  std::vector<std::optional<Rigid3d>> poses(rig_from_world_.size());
  for (size_t f = 0; f < rig_from_world_.size(); ++f) {
    if (has_rig_pose_[f]) poses[f] = FromPoseParams(rig_from_world_[f]);
  }
  std::vector<std::vector<double>> capture_offsets(rig_from_world_.size());
  for (const RigImage& image : dataset_.images) {
    const int c = image.camera_index;
    capture_offsets[image.frameset_index].push_back(CaptureTimeOfRow(
        time_offsets_[c], line_delays_[c],
        dataset_.cameras[c].camera.Height() / 2.0));
  }
  frameset_without_own_pose_ = FramesetsWithoutOwnPose(
      dataset_.frameset_times_s, poses, capture_offsets);
  // Written in place: the costs point into frameset_motions_.
  std::vector<FramesetMotion> motions;
  std::string error;
  CHECK(ComputeFramesetMotions(dataset_.frameset_times_s, poses, &motions,
                               &error, frameset_without_own_pose_,
                               &translation_stencils_))
      << error << " (checked by AdjustRig)";
  std::copy(motions.begin(), motions.end(), frameset_motions_.begin());
  translation_prior_ = EstimateTranslationPrior(
      motions,
      translations_started_ ? frameset_translations_
                            : std::vector<TranslationDerivatives>(),
      poses);
  if (!translations_started_) {
    for (size_t f = 0; f < motions.size(); ++f) {
      frameset_translations_[f] =
          Eigen::Map<const TranslationDerivatives>(&motions[f][9]);
    }
    translations_started_ = true;
  }
}

void RigAdjustment::AddTranslationPriors(
    const std::vector<char>& frameset_refined) {
  std::vector<double*> rig_poses(rig_from_world_.size(), nullptr);
  for (size_t f = 0; f < rig_poses.size(); ++f) {
    if (has_rig_pose_[f]) rig_poses[f] = rig_from_world_[f].data();
  }
  for (size_t f = 0; f < frameset_refined.size(); ++f) {
    if (!frameset_refined[f]) continue;
    for (TranslationPriorTerm& term : MakeTranslationPriorTerms(
             translation_stencils_, rig_poses, &frameset_translations_, f,
             f > 0 && frameset_refined[f - 1], &translation_prior_)) {
      translation_prior_costs_.push_back(std::move(term.cost));
      solver_->AddResidualBlock(translation_prior_costs_.back().get(), nullptr,
                                term.parameters);
    }
  }
}

std::vector<CameraCaptureTime> RigAdjustment::CaptureTimes() const {
  // A camera without observations has its blocks outside the problem: not
  // estimated.
  std::vector<char> camera_used(time_offsets_.size(), 0);
  for (const Observation& observation : observations_) {
    camera_used[CameraOf(observation)] = 1;
  }
  std::vector<CameraCaptureTime> result(time_offsets_.size());
  for (size_t c = 0; c < result.size(); ++c) {
    CameraCaptureTime& time = result[c];
    time.time_offset_s = time_offsets_[c];
    time.line_delay_s = line_delays_[c];
    time.time_offset_estimated =
        options_.estimate_time_offsets && camera_used[c] &&
        static_cast<int>(c) != dataset_.reference_camera;
    time.line_delay_estimated = options_.estimate_line_delays && camera_used[c];
  }
  return result;
}

}  // namespace rig_calibrator
