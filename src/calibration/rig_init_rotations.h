// Internal to the rig initialization (rig_init_problem.h): the rotation part
// of one RANSAC hypothesis, by greedy back-and-forth assignment (paper §3.3).
//
// With radial poses every image's rotation is complete (its third row is the
// cross product of the first two), so one camera with a rotation places a
// frameset's rotation (R_Q = R_P^T R_T) and one frameset places a camera's
// (R_P = R_T R_Q^T): framesets of 2-3 cameras still connect the whole rig.
// Each estimate is the consensus of its candidates: the candidate most
// others agree with (within max_rotation_deviation_deg; ties: the smaller
// sum of angles), refined as the chordal mean of the agreeing ones,
// NearestRotation(sum_k R_k).
#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "src/calibration/rig_init_problem.h"

namespace rig_calibrator {
namespace rig_init {

// Rotation part of a hypothesis: R_P per camera, R_Q per frameset.
struct Rotations {
  std::vector<std::optional<Eigen::Quaterniond>> cam_from_rig;
  std::vector<std::optional<Eigen::Quaterniond>> rig_from_world;
};

// The greedy back-and-forth assignment of one RANSAC trial. The seed
// frameset (>= 2 localized images) places its cameras relative to a base
// camera (the reference camera if there, else its first image's camera),
// whose frame is the hypothesis' rig frame; *base_camera is set to it.
// Then, alternately, framesets seen by cameras with a rotation and cameras
// seen in framesets with a rotation get theirs: estimates supported by two
// images first, then framesets resting on one image (a wrong one spoils
// that frameset only), and cameras resting on one image last (a wrong one
// spoils all that is placed through it). Finally two sweeps re-estimate
// every rotation but the base camera's from all the others, which repairs
// early choices made on little support.
Rotations AssignRotationsGreedily(const InitProblem& problem, int seed_frameset,
                                  int* base_camera);

}  // namespace rig_init
}  // namespace rig_calibrator
