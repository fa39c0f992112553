// The poses of a rendered rig dataset with exact ground truth: a calibrated
// pinhole camera walking around a TexturedScene (the mapping sequence, from
// which COLMAP builds the map) and a rig preset of synthetic_rig.h walking
// the same place (the calibration sequence).
//
// Both walk closed loops around the scene's walk ellipse (SceneWalk), looking
// outward with a varying heading, pitch and roll; the map camera on the
// ellipse itself, the rig on one 0.65 times as large, so the rig sees what
// the map saw from other positions. Views are spaced so consecutive map
// images change by similar amounts of translation and rotation (good overlap
// for sequential matching). Deterministic for a seed (the seed also selects
// the scene's textures).
//
// With a time model (time_model.frameset_rate_hz > 0) every rig image is
// taken at its own time and each row of a rolling shutter at its own
// (capture_model.h), with capture-time offsets and line delays
// (DrawCaptureTimes), and the rig moves on one continuous trajectory
// (rig_trajectory.h) through all framesets: it walks the scene's walk loop,
// 0.65 times as large, at speed_m_s, looking outward with the preset's
// swings of heading, pitch and roll and its bob, its heading turning at up
// to max_turn_rate_deg_s (the loop's own turn must stay below three
// quarters of it: at 1.5 m/s and 60 deg/s the courtyard, not the room or
// the street). Frameset f's time is t_f = (f + 1) / frameset_rate_hz, so
// that every capture time is positive, and rig_from_world[f] is the rig
// pose at t_f.
#pragma once

#include <colmap/base/camera.h>

#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/capture_model.h"
#include "src/synthetic/synthetic_rig.h"
#include "src/synthetic/textured_scene.h"

namespace rig_calibrator {

struct RenderedDatasetOptions {
  RigPreset preset = RigPreset::kRing5;
  SceneType scene = SceneType::kRoom;
  int num_map_images = 60;
  int num_framesets = 12;
  unsigned int seed = 0;
  // The map camera: PINHOLE, principal point at the image center.
  int map_width = 640;
  int map_height = 480;
  double map_focal_length = 400;
  // Height of the rig's camera centers' mean above the ground; 0: the
  // scene's eye height.
  double rig_height = 0;
  // The rig images' time model: its frameset_rate_hz (0, the default: every
  // frameset at one instant, global shutters; the images of earlier
  // versions), speed_m_s, max_turn_rate_deg_s, time offsets and line delays
  // (SyntheticRigOptions's meaning and checks; its other fields are not
  // used). Every offset must be within a quarter of the frameset period, so
  // that the images of a frameset lie within half a period of each other and
  // the framesets a period apart (RenderedDatasetPlan::TimestampTolerance).
  SyntheticRigOptions time_model;

  // False (with a message) for values outside their ranges.
  bool Check(std::string* error) const;
};

struct RenderedDatasetPlan {
  TexturedScene scene;
  colmap::Camera map_camera;                 // camera_id 1
  std::vector<std::string> map_image_names;  // "map_000012.png"
  std::vector<Rigid3d> map_cam_from_world;
  // The preset's true cameras and cam_from_rig, and rig_from_world per
  // frameset (the planned poses, at t_f). With a time model also its
  // frameset times, offsets, line delays, trajectory and body_from_rig.
  RigGroundTruth rig;
  // "000012"; with a time model the time stamp of t_f (Timestamp).
  std::vector<std::string> frameset_names;

  bool HasTimeModel() const { return rig.trajectory.has_value(); }
  // "cam3/000012.png": the image of a rig camera in a frameset, relative to
  // the rig image folder; with a time model "cam3/<Timestamp>.png" of the
  // image's capture time t_f + delta_c (its top row's), so that images of
  // a frameset have different, close numeric names, as an unsynchronized
  // rig records them.
  std::string RigImageName(int camera_index, int frameset_index) const;
  // With a time model: how camera `camera_index` took its image of frameset
  // `frameset_index` (the row times and the motion).
  ImageCapture RigImageCapture(int camera_index, int frameset_index) const;
  // With a time model: the rig_calibrator --RigCalibrator.timestamp_tolerance
  // (in the time stamps' unit, nanoseconds) that groups the images into the
  // framesets: half the frameset period.
  double TimestampTolerance() const;
};

// A time in seconds as the integer number of nanoseconds that names its
// images ("1200000000" for 1.2 s; --RigCalibrator.timestamp_unit_s 1e-9).
std::string Timestamp(double time_s);

// Fails (with a message) for invalid options, or when a camera would stand
// inside or within 0.25 m of a surface (with a time model: when its top or
// bottom row is taken), or when the scene's loop turns too fast for the
// time model's speed and turn rate.
bool PlanRenderedDataset(const RenderedDatasetOptions& options,
                         RenderedDatasetPlan* plan, std::string* error);

}  // namespace rig_calibrator
