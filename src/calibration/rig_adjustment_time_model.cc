// The final bundle adjustment's time model (final_bundle_adjuster.h): the
// rig's motion around each frameset from the current rig poses, and the
// estimated offsets and line delays.
#include <glog/logging.h>

#include <algorithm>

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
