// The rig presets of synthetic_rig.h as camera specifications in a body
// frame, with the motion profile of the platform that carries them. Internal
// to the synthetic data generator.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/rig_trajectory.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// Most cameras of a ring (SyntheticRigOptions::ring_num_cameras): 10 degrees
// apart.
constexpr int kMaxRingCameras = 36;

// One camera of a preset, placed in the body frame (x forward, y left, z up).
struct CameraSpec {
  std::string model_name;
  int width = 0;
  int height = 0;
  std::vector<double> params;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // in the body frame
  double yaw_deg = 0;    // viewing direction about z, 0 = forward, 90 = left
  double pitch_deg = 0;  // positive = looking up
  double roll_deg = 0;   // about the viewing direction
};

struct PresetDefinition {
  std::vector<CameraSpec> cameras;
  MotionProfile motion;
};

// body_from_cam for a camera looking along (yaw, pitch) with a roll about its
// viewing direction. Camera axes: x right, y down, z forward.
Rigid3d BodyFromCamera(const CameraSpec& spec);

// The definition of a preset; for ring5 with ring_num_cameras > 0, the ring
// of that many cameras (SyntheticRigOptions::ring_num_cameras).
PresetDefinition MakePresetDefinition(RigPreset preset, int ring_num_cameras);

// Replaces the cameras of the stereo_pair definition by num_pairs copies of
// the pair, copy k 0.25 k m above the first; with alternate_facing the odd
// copies are turned to face backward and moved 0.3 m behind
// (SyntheticRigOptions::stereo_num_pairs).
void ReplicateStereoPair(int num_pairs, bool alternate_facing,
                         PresetDefinition* definition);

// The true cameras (camera ids 1, 2, ...) and extrinsics of a rig definition
// (no rig poses); the rig frame is camera 0's.
RigGroundTruth TruthOfDefinition(const PresetDefinition& definition);

}  // namespace rig_calibrator
