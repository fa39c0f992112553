// Synthetic rig calibration problems with a known answer, for tests and
// benchmarks: a rig preset (true intrinsics and camera-from-rig poses), a
// smooth trajectory of rig poses, and per image 2D-3D correspondences made by
// projecting map points with COLMAP's camera models, with Gaussian pixel
// noise, wrong matches (outliers) and missing images.
//
// With a time model (frameset_rate_hz > 0) the rig moves continuously
// (rig_trajectory.h) and every image is taken at its own time, each row of a
// rolling-shutter camera at its own (capture_model.h).
//
// Frames: the world is z-up. Each preset places its cameras in a "body" frame
// (x forward, y left, z up; for the car, the origin is on the ground below the
// car's center); the rig frame is camera 0's frame (cam_from_rig[0] is the
// identity), as everywhere in the project.
#pragma once

#include <colmap/base/camera.h>

#include <optional>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/rig/rig_dataset.h"
#include "src/synthetic/rig_trajectory.h"

namespace rig_calibrator {

enum class RigPreset { kRing5, kFisheyeHelmet5, kCarSurround4, kStereoPair };

// Parses/prints "ring5", "fisheye_helmet5", "car_surround4", "stereo_pair".
bool RigPresetFromName(const std::string& name, RigPreset* preset);
std::string RigPresetName(RigPreset preset);
std::vector<RigPreset> AllRigPresets();

struct RigGroundTruth {
  std::vector<colmap::Camera> cameras;    // true intrinsics
  std::vector<Rigid3d> cam_from_rig;      // camera 0 (the reference) = identity
  std::vector<Rigid3d> rig_from_world;    // per frameset
  std::vector<std::string> camera_names;  // "cam0", ...
  // With a time model (SyntheticRigOptions::frameset_rate_hz > 0; else all
  // empty): per frameset its nominal time t_f = f / frameset_rate_hz
  // (seconds; rig_from_world[f] is the rig pose at t_f), per camera its
  // capture-time offset delta_c (seconds, camera 0's is 0) and line delay
  // rho_c (seconds per row, 0: global shutter): camera c captures the row
  // through pixel y at t_f + delta_c + rho_c (y - 0.5) (capture_model.h).
  std::vector<double> frameset_times_s;
  std::vector<double> time_offsets_s;
  std::vector<double> line_delays_s;
  // With a time model: the rig's motion, world_from_body(t), and the rig
  // frame in the body frame, so that rig_from_world(t) = (world_from_body(t)
  // * body_from_rig)^-1 (RigFromWorldAtTime in capture_model.h).
  std::optional<RigTrajectory> trajectory;
  Rigid3d body_from_rig;
};

// The true cameras and extrinsics of a preset (rig_from_world is empty):
//  ring5: 5 outward-looking OPENCV 640x480 cameras at 72 degree steps on a
//    0.15 m ring, f 405-445 px, k1 ~ -0.3, k2 ~ 0.08, small p1, p2, principal
//    points up to 20 px off-center, pitched by a few degrees.
//  fisheye_helmet5: 5 OPENCV_FISHEYE 640x480 cameras with a 145-155 degree
//    diagonal field of view on a 0.12 m helmet ring, pitched 10-15 degrees
//    up or down.
//  car_surround4: on a 4.5 x 1.8 m car, front OPENCV 960x600 (0.6 m high,
//    12 degrees down), left and right mirror OPENCV_FISHEYE 800x600 with a
//    160 degree diagonal field of view (1.0 m, 28-30 degrees down), back
//    RADIAL 640x480 (1.1 m, 20 degrees down).
//  stereo_pair: EuRoC-like forward-looking OPENCV 752x480 pair, 0.11 m
//    baseline, axes parallel up to a 0.2 degree misalignment.
RigGroundTruth MakeRigPreset(RigPreset preset);

struct SyntheticRigOptions {
  RigPreset preset = RigPreset::kRing5;
  int num_framesets = 30;
  int points_per_image = 300;
  // Standard deviation of the Gaussian noise on each pixel coordinate.
  double noise_px = 0.5;
  // Share of each image's correspondences whose 3D point is replaced by
  // another map point that projects more than 20 px away (wrong matches).
  double outlier_ratio = 0.3;
  // Share of all images dropped (no image at all); no frameset is emptied.
  double missing_image_ratio = 0.1;
  // Range of the distance of an image's map points from its camera center.
  double min_depth = 2.0, max_depth = 10.0;
  // Share of the correct correspondences placed on a dominant plane (the
  // ground, z = 0) when the ground is seen within the depth range; the others
  // fall back to free-space points.
  double near_planar_ratio = 0.0;
  // Share of the correct correspondences that re-observe map points created
  // by images of the previous framesets (feature tracks, shared point3D_id),
  // as far as such points are visible; the rest are new map points.
  double track_ratio = 0.5;
  // Side of the window, as a share of the image width and height, that holds
  // an image's correspondences; the window is placed at random per image
  // (1: the whole image). Small windows model images whose features cluster
  // on one textured region, leaving the image's own intrinsics poorly
  // determined while all images of a camera together still cover it.
  double feature_window = 1.0;
  // ring5 only: the number of cameras on the ring (0: the preset's 5; at
  // most 36), evenly spaced on its 0.15 m circle, looking outwards. Camera i
  // has the model, size, distortion, pitch, roll and height of ring5's camera
  // i mod 5 and its focal lengths scaled by 1 + 0.03 * floor(i / 5). E.g. 10
  // for a 10-camera rig (runtime benchmark).
  int ring_num_cameras = 0;
  // Every camera's image scaled to this many rows (0: the preset's sizes):
  // width, focal lengths and principal point with it (colmap::Camera::
  // Rescale), distortion unchanged, so each camera sees what it saw, more
  // finely. E.g. 1080 for the rows a 1080p rolling shutter reads out.
  int image_height = 0;
  // Map images (synthetic_map.h): how many, the Gaussian noise on their
  // observations (pixels per coordinate), and the error of the map points
  // given to the calibration (map units per coordinate, Gaussian): a map's
  // points are only as good as its triangulation. 0 map images: none (the
  // default; the map points are then exact unless map_point_noise > 0).
  int num_map_images = 0;
  // At most this many observations per map image (0: every visible point),
  // the points that rig images observe first: a COLMAP map image holds a few
  // thousand of the points in its view.
  int map_observations_per_image = 0;
  double map_noise_px = 0.5;
  double map_point_noise = 0.0;
  // A map as structure from motion makes it (with num_map_images > 0): the
  // map images' poses given to the calibration are off by
  // map_pose_noise_deg (rotation, degrees per axis) and map_pose_noise
  // (centre, map units per axis), Gaussian and independent per image, plus
  // a drift that grows linearly along the map images to map_drift_deg (a
  // rotation about the vertical through the first rig centre) and
  // map_scale_drift (relative scale about that centre) at the last one;
  // with triangulate_map_points every map point that >= 2 map images
  // observe is triangulated from their noisy observations through those
  // poses (so its error follows theirs, as in a real map), the others keep
  // map_point_noise. The correspondences and map_points3D carry the map's
  // points; the rig images observe the true ones.
  double map_pose_noise_deg = 0.0;
  double map_pose_noise = 0.0;
  double map_drift_deg = 0.0;
  double map_scale_drift = 0.0;
  bool triangulate_map_points = false;
  // stereo_pair only: that many copies of the pair, copy k 0.25 k m above
  // the first (several pairs facing the same way: all principal axes
  // parallel); with stereo_alternate_facing the odd copies face backward,
  // 0.3 m behind (front/rear pairs: parallel and anti-parallel axes).
  int stereo_num_pairs = 1;
  bool stereo_alternate_facing = false;
  // The rig only rotates about a fixed point: every frameset's rig center is
  // the first one's (no translation between framesets).
  bool rotation_only = false;
  // Map units per metre: every map point and translation (rig poses,
  // cam_from_rig) is multiplied by it, pixels are unchanged. E.g. 1000 for a
  // map in millimetres; the calibration must be the same up to this scale.
  double map_scale = 1.0;
  // The time model. 0 (the default): every frameset is taken at one
  // instant by global-shutter cameras, the rig moving frameset by frameset
  // along the preset's profile (the data of earlier versions, unchanged for
  // every seed). > 0: the rig moves continuously (rig_trajectory.h) and
  // frameset f is taken at t_f = f / frameset_rate_hz seconds, each camera
  // at its own offset and each row of a rolling shutter at its own time
  // (capture_model.h); the truth and the dataset carry the times.
  double frameset_rate_hz = 0;
  // With frameset_rate_hz > 0: the rig's ground speed (map units per second
  // before map_scale, i.e. metres) and the peak rate of its heading
  // (degrees per second); the profile's pitch and roll oscillations are
  // played at the same pace.
  double speed_m_s = 1.5;
  double max_turn_rate_deg_s = 60;
  // With frameset_rate_hz > 0: > 0, the body bobs up and down at this
  // frequency (Hz) with the preset's amplitude, instead of the preset's
  // own bob (MotionProfile::bob_period_s); e.g. a vibration faster than
  // the framesets follow.
  double bob_hz = 0;
  // With frameset_rate_hz > 0: the capture-time offset delta_c of every
  // camera but the reference camera 0 (whose offset is 0), drawn uniformly
  // in [-max_time_offset_s, max_time_offset_s] (seconds); or, when
  // time_offsets_s is not empty, given: one per camera, the first 0.
  double max_time_offset_s = 0;
  std::vector<double> time_offsets_s;
  // With frameset_rate_hz > 0: the line delay rho_c of every camera, drawn
  // uniformly in [min_line_delay_s, max_line_delay_s] (seconds per row; 0:
  // global shutter); or, when line_delays_s is not empty, given: one per
  // camera. A camera's readout (line delay times its rows) must fit in the
  // frameset period 1 / frameset_rate_hz.
  double min_line_delay_s = 0, max_line_delay_s = 0;
  std::vector<double> line_delays_s;
  unsigned int seed = 0;

  // False (with a message naming the option) for values outside their
  // ranges, and for time offsets, line delays, a speed or a turn rate other
  // than the defaults without frameset_rate_hz > 0.
  bool Check(std::string* error) const;
};

// The preset's motion profile with options.bob_hz applied (the time
// model's trajectory).
MotionProfile TimeModelMotion(const SyntheticRigOptions& options,
                              MotionProfile motion);

struct SyntheticRig {
  // Cameras: same model and size as the truth, parameters = initial guesses
  // (COLMAP's defaults: focal 1.2 * max(width, height), principal point at the
  // image center, zero distortion); names cam0, cam1, ...; images
  // "camK/000012.png"; frameset names "000012"; with a time model the
  // frameset times (the truth's).
  RigDataset dataset;
  RigGroundTruth truth;
  // Per dataset image, per correspondence: 1 for a wrong match.
  std::vector<std::vector<char>> is_outlier;
  // The true map points, by point3D_id (the dataset's are these plus
  // map_point_noise).
  std::vector<Eigen::Vector3d> true_points3D;
  // The true pose of every dataset map image.
  std::vector<Rigid3d> true_map_cam_from_world;
};

// Deterministic for a seed. With invalid options, logs the error and returns a
// rig without images.
SyntheticRig GenerateSyntheticRig(const SyntheticRigOptions& options);

// Per camera of truth (its cameras set) the capture-time offset and line
// delay of the time model of `options` (frameset_rate_hz > 0): given
// (time_offsets_s, line_delays_s) or drawn uniformly in their ranges from a
// random stream of their own (seed + 4), so that they do not change the
// other draws of the data and the same seed gives the same values whatever
// the preset. Sets truth->time_offsets_s and truth->line_delays_s.
void DrawCaptureTimes(const SyntheticRigOptions& options,
                      RigGroundTruth* truth);

// Keeps the rig correspondences of points that at least two map images
// observe, as in a COLMAP map, where every point has a track (with map
// images; without, nothing changes): then every point can be refined with
// the map, and the map adjustment's gauge is free.
void KeepCorrespondencesWithMapTracks(SyntheticRig* rig);

// The sub-problem made of the given framesets (indices into rig, in the given
// order, renumbered from 0; names and times kept), e.g. for the short-sequence
// robustness experiments (paper section 5.3: 10 framesets). Indices out of
// range or repeated are logged and skipped. The dataset's frameset times are
// dropped (with a warning) when the order is not increasing in time.
SyntheticRig SelectFramesets(const SyntheticRig& rig,
                             const std::vector<int>& framesets);

// "000012": the name of frameset 12, zero-padded to 6 digits (also the
// number in other numbered file names, e.g. of rendered map images).
std::string FramesetName(int frameset);

// Gives every dataset camera its true intrinsics, flagged as known (the
// `known*` methods).
void SetKnownIntrinsics(SyntheticRig* rig);

}  // namespace rig_calibrator
