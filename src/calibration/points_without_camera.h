// The map points a camera observes, placed by every other image that sees
// them: the points on which the model choice on the adjusted rig
// (model_choice_after_adjustment.h) compares a camera's candidate models.
//
// Why: the final adjustment refines the points with the camera's current
// model. Where the camera's own observations dominate a point (a point only
// it sees, or many more of its rays than the other images'), the refined
// point keeps that model's error, and a candidate that imitates the current
// model fits it best. On synthetic ring5 at 5 Hz and 1080 rows with offsets
// and rolling shutters (docs/time_model.md), the camera upgrade chose
// SIMPLE_RADIAL_FISHEYE for a pinhole lens from the unsynchronized data, and
// on the adjusted rig OPENCV_FISHEYE (held out 0.670 px) beat the true OPENCV
// (0.757 px); on the 500 x 10 benchmark with the time model the same
// happened to cam7, whose points the map images see too.
//
// Per point, from the other observations' rays (origin o_i, unit direction
// d_i in the world):
//
//   X = argmin sum_i w_i |(I - d_i d_i^T)(X - o_i)|^2,
//
// the squared distances to the rays, first with w_i = 1 and then with
// w_i = 1 / |X_1 - o_i|^2 (X_1 the first solution): the angle between the ray
// and the point, the same for near and far images. The rays are the final
// inliers of the other calibrated rig cameras, through their final
// intrinsics and the rig pose of their own capture instant (with the
// capture-time model's kept kinds, as in the adjustment), and, where the map
// images' observations were residuals of the adjustment, their observations
// that were not rejected, through the adjusted map images and cameras.
// A point with fewer than two such rays, rays within min_angle_deg of each
// other, or behind one of them keeps its map position (the input's, which
// the camera did not place either).
#pragma once

#include <colmap/base/camera.h>

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "src/calibration/capture_time_model.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

struct PointsWithoutCameraOptions {
  // The rays' smallest spread, an angle theta: lambda_min / lambda_max of
  // sum (I - d_i d_i^T) at least sin^2(theta / 2), which is that ratio for
  // two rays theta apart ((1 - cos theta) / 2). At 2 degrees and 0.5 px of
  // noise at f = 900 px, a two-ray depth is within about 1.6 %.
  double min_angle_deg = 2.0;
  // With the map images' observations (the final adjustment's
  // use_map_observations).
  bool map_observations = true;
};

// Per point3D_id among `camera_index`'s final inliers: its position from
// every other observation (see the top), or its map position.
std::unordered_map<int64_t, Eigen::Vector3d> PointsWithoutCamera(
    const RigDataset& dataset, const RigCalibration& calibration,
    const CaptureTimeModel& time_model, int camera_index,
    const PointsWithoutCameraOptions& options);

}  // namespace rig_calibrator
