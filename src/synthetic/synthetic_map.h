// The map of a synthetic rig dataset (synthetic_rig.h): map images that
// observe the generated map points, and the map points as a map would hold
// them (true positions plus triangulation error). Internal to the generator.
#pragma once

#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// With options.map_point_noise > 0, moves every map point of the dataset
// (its correspondences' point3D and map_points3D) by Gaussian noise of that
// standard deviation per coordinate. With options.num_map_images > 0 adds to
// rig->dataset one PINHOLE map camera (the size of camera 0, focal 0.7 x its
// width, principal point at the center) and num_map_images map images, the
// m-th near the true pose of rig camera m mod C in frameset
// m * F / num_map_images (0.2 map units and 3 degrees away at random), each
// observing every true map point in front of it, inside the image and
// within twice max_depth, with map_noise_px pixel noise. Fills
// rig->dataset.map_points3D (every map point) and true_map_cam_from_world.
// Needs rig->true_points3D and the truth; draws from its own random stream
// (seed + 1).
void AddSyntheticMap(const SyntheticRigOptions& options, SyntheticRig* rig);

}  // namespace rig_calibrator
