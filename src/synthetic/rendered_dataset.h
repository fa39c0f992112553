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
#pragma once

#include <colmap/base/camera.h>

#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"
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

  // False (with a message) for values outside their ranges.
  bool Check(std::string* error) const;
};

struct RenderedDatasetPlan {
  TexturedScene scene;
  colmap::Camera map_camera;                 // camera_id 1
  std::vector<std::string> map_image_names;  // "map_000012.png"
  std::vector<Rigid3d> map_cam_from_world;
  // The preset's true cameras and cam_from_rig, and rig_from_world per
  // frameset.
  RigGroundTruth rig;
  std::vector<std::string> frameset_names;  // "000012"

  // "cam3/000012.png": the image of a rig camera in a frameset, relative to
  // the rig image folder.
  std::string RigImageName(int camera_index, int frameset_index) const;
};

// Fails (with a message) for invalid options, or when a camera would stand
// inside or within 0.25 m of a surface.
bool PlanRenderedDataset(const RenderedDatasetOptions& options,
                         RenderedDatasetPlan* plan, std::string* error);

}  // namespace rig_calibrator
