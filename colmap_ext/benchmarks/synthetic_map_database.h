// A COLMAP 3.8 database and the matching sparse map (colmap::Reconstruction)
// made of random SIFT-like descriptors, with rig images whose features
// re-observe map points: the input of the localization step (MapLocalizer)
// without images, for throughput measurements and tests.
//
// Map points lie uniformly in a 20 m cube around the origin. Map point p has
// a random base descriptor (half of the 128 bins empty, the rest |N(0, 1)|,
// L2 norm 512 like COLMAP's SIFT); each of its observations is the base plus
// per-bin Gaussian noise (`descriptor_noise`, 10 gives ~0.25 rad between two
// observations), renormalized. Point p is seen by `track_length` consecutive
// map images starting at a random one (a ring), so that neighbouring map
// images share points as along a trajectory. Map images have identity poses
// and random keypoint positions: the localizer only uses their tracks.
//
// Rig images are geometrically consistent, so that their 2D-3D
// correspondences can be fed to the radial pose estimator: a SIMPLE_PINHOLE
// camera (focal `rig_focal_px`, principal point at the image center) 40 m
// from the origin looks at it; its keypoints of map points are projections
// (plus `keypoint_noise_px` Gaussian noise) of points of a few neighbouring
// map images that fall inside the image; the rest are distractors (random
// positions and descriptors).
#pragma once

#include <colmap/base/reconstruction.h>
#include <colmap/util/types.h>

#include <string>
#include <unordered_map>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

struct SyntheticMapDatabaseOptions {
  int num_map_images = 300;
  int features_per_map_image = 2000;
  // Of which observe a map point (the rest are distractors).
  int points_per_map_image = 1200;
  int track_length = 4;
  int num_rig_images = 40;
  // Rig images go round-robin to cameras cam0/, cam1/, ...
  int num_rig_cameras = 2;
  int features_per_rig_image = 2000;
  // Of which re-observe map points (as many as are in view).
  int map_points_per_rig_image = 1000;
  double descriptor_noise = 10;
  double keypoint_noise_px = 0.5;
  int image_width = 640, image_height = 480;
  double rig_focal_px = 400;
  unsigned int seed = 0;

  // False (with a message) for values outside their ranges.
  bool Check(std::string* error) const;
};

struct SyntheticMapDatabase {
  colmap::Reconstruction map;
  // Database names of the map ("map/001000.png") and rig images
  // ("cam0/010000.png").
  std::vector<std::string> map_image_names;
  std::vector<std::string> rig_image_names;
  // Per rig image: the true cam_from_world, and keypoint index -> map point
  // of every keypoint that observes one.
  std::vector<Rigid3d> rig_cam_from_world;
  std::vector<std::unordered_map<colmap::point2D_t, colmap::point3D_t>>
      rig_planted;
};

// Writes a new database at `database_path` (the file must not exist) and
// fills *scene. Deterministic for a seed. False with *error on invalid
// options or when the file exists or cannot be written.
bool WriteSyntheticMapDatabase(const SyntheticMapDatabaseOptions& options,
                               const std::string& database_path,
                               SyntheticMapDatabase* scene, std::string* error);

}  // namespace rig_calibrator
