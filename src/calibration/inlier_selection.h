// Which correspondences a stage of the pipeline uses: those that the current
// rig explains. Every image of a posed frameset (calibrated camera, rig pose)
// gets its inlier mask; images of other framesets get none. This also brings
// in images that could not be localized on their own but whose frameset was
// posed by the other cameras.
#pragma once

#include <vector>

#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

// The image's camera is calibrated and its frameset has a rig pose.
bool FramesetPosed(const RigCalibration& calibration, const RigImage& image);

// Inliers of the radial rig: radial reprojection error (about the camera's
// current principal point) below max_error_px.
void SelectRadialInliers(const RigDataset& dataset, double max_error_px,
                         RigCalibration* calibration);

// Inliers of the full calibration: in front of the camera and reprojected
// within max_error_px, with the point where a final adjustment refined it
// (calibration->refined_points3D), else the map's: a refined map can have
// moved away from the input's (on the real EuRoC pair's self-calibrated map
// every rig observation but one was beyond 10 px of the input points).
// With capture times (the final adjustment's time model: per dataset camera
// its offset and line delay in seconds, seconds per row; empty: 0) the
// point is taken in the rig frame of its row's instant (frameset_motion.h,
// the motion from the current rig poses and the dataset's frameset times):
// an unsynchronized camera's correct correspondences are tens of pixels
// from the synchronized projection.
void SelectFullInliers(const RigDataset& dataset, double max_error_px,
                       RigCalibration* calibration,
                       const std::vector<double>& time_offsets_s = {},
                       const std::vector<double>& line_delays_s = {});

}  // namespace rig_calibrator
