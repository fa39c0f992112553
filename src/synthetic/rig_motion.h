// The motion of a synthetic rig: its trajectory from a preset's motion
// profile. Internal to the synthetic data generator.
#pragma once

#include <random>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/rig_trajectory.h"

namespace rig_calibrator {

// world_from_body along the trajectory, frameset by frameset. The heading
// turns slowly (yaw_rate) while yaw, pitch and roll oscillate, so the rig
// sees the map under varied rotations.
// Draws 4 phases from *rng.
std::vector<Rigid3d> MakeTrajectory(const MotionProfile& motion,
                                    int num_framesets, std::mt19937* rng);

}  // namespace rig_calibrator
