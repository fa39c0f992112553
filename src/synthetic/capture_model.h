// The capture model of the synthetic time model (unsynchronized cameras,
// rolling shutter; SyntheticRigOptions::frameset_rate_hz > 0): when each
// image row is taken, and where a map point appears in an image taken from a
// moving rig.
//
// Camera c in frameset f (nominal time t_f) captures the image row through
// the pixel coordinate y at
//   t(y) = t_f + delta_c + rho_c (y - 0.5),
// with delta_c the camera's capture-time offset (0 for the reference camera
// 0, whose frame is the rig frame) and rho_c its line delay (seconds per
// row; 0: a global shutter, every row at t_f + delta_c). Pixels follow
// COLMAP (the centre of the top-left pixel is (0.5, 0.5)), so the centre of
// row r = 0, 1, ... (y = r + 0.5) is captured at t_f + delta_c + rho_c r, and
// a sub-pixel y lies linearly between its rows' times. rig_from_world[f] of
// the ground truth is the rig pose at t_f, the time of the centre of camera
// 0's top row.
//
// A map point X appears at the pixel (x, y) that is its projection by the
// pose of its own row:
//   (x, y) = pi(cam_from_world(t(y)) X),
// a fixed point in y, solved by the iteration y_k+1 = pi_y(cam_from_world(
// t(y_k)) X). It contracts with the factor L = rho_c |d pi_y / dt|, the
// point's image speed in rows per row of readout: about 0.01-0.1 for 20-30
// microseconds per row at 1.5 m/s and 60 degrees/s, so a few iterations reach
// 1e-10 px. Points for which it does not converge (L >= 1: the point moves
// faster than the shutter scans) or that pass behind the camera are not
// observed.
#pragma once

#include <colmap/base/camera.h>

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/rig_trajectory.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// The capture of one image: the rig's motion and the image's row times.
struct ImageCapture {
  const RigTrajectory* trajectory = nullptr;
  // Where the trajectory lies in the world: world_from_body(t) =
  // world_from_trajectory * trajectory->WorldFromBody(t). Unset (the
  // identity, not composed) for the synthetic generator's and the rendered
  // datasets' trajectories, which are in the world frame; set where a
  // trajectory's piece must stand at a given place (a renderer's test).
  std::optional<Rigid3d> world_from_trajectory;
  Rigid3d body_from_rig;  // RigGroundTruth::body_from_rig
  Rigid3d cam_from_rig;
  double top_row_time_s = 0;  // t_f + delta_c: when y = 0.5 is captured
  double line_delay_s = 0;    // rho_c, seconds per row

  // t(y) = t_f + delta_c + rho_c (y - 0.5).
  double RowTime(double y) const {
    return top_row_time_s + line_delay_s * (y - 0.5);
  }
  // cam_from_rig * rig_from_world(t), rig_from_world(t) = (world_from_body(t)
  // * body_from_rig)^-1 (as the ground truth's rig_from_world[f] at t_f).
  Rigid3d CamFromWorldAt(double time_s) const;
};

// The pose of every image row r = 0 .. num_rows - 1 as a renderer needs it:
// cam_from_world(t(r + 0.5)), the pose when the row's pixel centres are
// read out. A sensor row is exposed as a whole, so every point of a pixel
// (any sample of it) is seen with its row's pose.
std::vector<Rigid3d> CamFromWorldPerRow(const ImageCapture& capture,
                                        int num_rows);

// The rig pose at time t of a ground truth with a time model (its trajectory
// set): (world_from_body(t) * body_from_rig)^-1.
Rigid3d RigFromWorldAtTime(const RigGroundTruth& truth, double time_s);

// The capture of the image of `camera` in `frameset` of a ground truth with a
// time model.
ImageCapture CaptureOfImage(const RigGroundTruth& truth, int camera,
                            int frameset);

// The rolling-shutter iteration stops when two iterates agree to this, or
// fails after that many iterations.
constexpr double kRollingShutterTolerancePx = 1e-10;
constexpr int kMaxRollingShutterIterations = 50;

// The pixel (x, y) = pi(cam_from_world(t(y)) X) of the world point X, by the
// fixed-point iteration above, started at the middle row (y = height / 2),
// until two iterates agree to kRollingShutterTolerancePx. False when an
// iterate is behind the camera or not finite, or without convergence after
// kMaxRollingShutterIterations. The pixel may lie outside the image (the
// caller decides).
bool ProjectWithRollingShutter(const colmap::Camera& camera,
                               const ImageCapture& capture,
                               const Eigen::Vector3d& point_in_world,
                               Eigen::Vector2d* xy);


}  // namespace rig_calibrator
