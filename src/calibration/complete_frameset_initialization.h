// Heng et al.'s rig initialization, as the paper's baselines Inf+K, Inf+K+RI
// and Inf+RD use it (methods known, known_refine, rd): the extrinsics are
// those of the complete frameset (every camera localized on its own) with the
// most inliers, and every other frameset's rig pose is the average of what
// its localized cameras say, given those extrinsics. Unlike the robust rig
// initialization (rig_initializer.h) it needs a complete frameset and trusts
// that one frameset's poses.
#pragma once

#include <string>
#include <vector>

#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

// Sets calibration->cam_from_rig (reference camera: identity),
// camera_calibrated (all) and rig_from_world (framesets with a localized
// image) from calibration->images[i].single_image_cam_from_world. False with
// `error` when no frameset is complete.
bool InitializeRigFromCompleteFrameset(const RigDataset& dataset,
                                       RigCalibration* calibration,
                                       std::string* error);

// The rig pose of a frameset from per-camera estimates of rig_from_world
// (cam_from_rig^-1 * cam_from_world of each camera): rotation the chordal L2
// mean (the nearest rotation of the summed matrices), center the mean of the
// rig centers.
Rigid3d AverageRigFromWorld(const std::vector<Rigid3d>& estimates);

}  // namespace rig_calibrator
