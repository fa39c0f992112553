#include "src/calibration/rig_init_rotations.h"

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace rig_init {
namespace {

// Consensus rotations compare every candidate with every other: an evenly
// spread subset bounds the quadratic cost.
constexpr int kMaxRotationCandidates = 50;
// Sweeps re-estimating every rotation after the greedy assignment.
constexpr int kNumRotationSweeps = 2;

struct RotationEstimate {
  Eigen::Quaterniond rotation;
  int support = 0;  // candidates within the rotation tolerance of it
};

// The consensus of the candidates (see the header), from an evenly spread
// subset of at most kMaxRotationCandidates of them.
std::optional<RotationEstimate> ConsensusRotation(
    std::vector<Eigen::Quaterniond> candidates, double max_angle) {
  if (candidates.empty()) return std::nullopt;
  if (candidates.size() > kMaxRotationCandidates) {
    std::vector<Eigen::Quaterniond> subset;
    for (int k = 0; k < kMaxRotationCandidates; ++k) {
      subset.push_back(
          candidates[k * candidates.size() / kMaxRotationCandidates]);
    }
    candidates.swap(subset);
  }
  int best = 0, best_support = -1;
  double best_angle_sum = 0;
  for (size_t m = 0; m < candidates.size(); ++m) {
    int support = 0;
    double angle_sum = 0;
    for (const Eigen::Quaterniond& other : candidates) {
      const double angle = RotationDifferenceRad(candidates[m], other);
      if (angle < max_angle) {
        ++support;
        angle_sum += angle;
      }
    }
    if (support > best_support ||
        (support == best_support && angle_sum < best_angle_sum)) {
      best = m;
      best_support = support;
      best_angle_sum = angle_sum;
    }
  }
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Eigen::Quaterniond& other : candidates) {
    if (RotationDifferenceRad(candidates[best], other) < max_angle) {
      sum += other.toRotationMatrix();
    }
  }
  RotationEstimate estimate;
  estimate.rotation = Eigen::Quaterniond(NearestRotation(sum));
  estimate.support = best_support;
  return estimate;
}

// R_Q of a frameset from its images of cameras with a rotation:
// R_Q = R_P^T R_T per image.
std::optional<RotationEstimate> FramesetRotation(const InitProblem& problem,
                                                 const Rotations& rotations,
                                                 int frameset) {
  std::vector<Eigen::Quaterniond> candidates;
  for (const int index : problem.images_of_frameset[frameset]) {
    const LocalizedImage& image = problem.images[index];
    if (rotations.cam_from_rig[image.camera]) {
      candidates.push_back(rotations.cam_from_rig[image.camera]->conjugate() *
                           image.cam_from_world.rotation);
    }
  }
  return ConsensusRotation(candidates, problem.max_rotation_deviation);
}

// R_P of a camera from its images in framesets with a rotation:
// R_P = R_T R_Q^T per image.
std::optional<RotationEstimate> CameraRotation(const InitProblem& problem,
                                               const Rotations& rotations,
                                               int camera) {
  std::vector<Eigen::Quaterniond> candidates;
  for (const int index : problem.images_of_camera[camera]) {
    const LocalizedImage& image = problem.images[index];
    if (rotations.rig_from_world[image.frameset]) {
      candidates.push_back(
          image.cam_from_world.rotation *
          rotations.rig_from_world[image.frameset]->conjugate());
    }
  }
  return ConsensusRotation(candidates, problem.max_rotation_deviation);
}

// Assigns the pending estimates with at least min_support. Returns whether
// anything was assigned.
bool AssignSupported(
    const std::vector<std::optional<RotationEstimate>>& pending,
    int min_support,
    std::vector<std::optional<Eigen::Quaterniond>>* rotations) {
  bool assigned = false;
  for (size_t k = 0; k < pending.size(); ++k) {
    if (pending[k] && pending[k]->support >= min_support) {
      (*rotations)[k] = pending[k]->rotation;
      assigned = true;
    }
  }
  return assigned;
}

// The seed frameset's rotation (its base image's) and its cameras'.
Rotations SeedRotations(const InitProblem& problem, int seed_frameset,
                        int* base_camera) {
  Rotations rotations;
  rotations.cam_from_rig.resize(problem.num_cameras);
  rotations.rig_from_world.resize(problem.num_framesets);
  const std::vector<int>& seed_images =
      problem.images_of_frameset[seed_frameset];
  int base = seed_images.front();
  for (const int index : seed_images) {
    if (problem.images[index].camera == problem.reference_camera) base = index;
  }
  *base_camera = problem.images[base].camera;
  const Eigen::Quaterniond seed_rotation =
      problem.images[base].cam_from_world.rotation;
  rotations.rig_from_world[seed_frameset] = seed_rotation;
  for (const int index : seed_images) {
    const LocalizedImage& image = problem.images[index];
    rotations.cam_from_rig[image.camera] =
        image.cam_from_world.rotation * seed_rotation.conjugate();
  }
  return rotations;
}

// The greedy pass: assigns the unassigned rotations until none can be.
void AssignGreedily(const InitProblem& problem, Rotations* rotations) {
  std::vector<std::optional<RotationEstimate>> pending_framesets(
      problem.num_framesets);
  std::vector<std::optional<RotationEstimate>> pending_cameras(
      problem.num_cameras);
  while (true) {
    for (int j = 0; j < problem.num_framesets; ++j) {
      pending_framesets[j] = rotations->rig_from_world[j]
                                 ? std::nullopt
                                 : FramesetRotation(problem, *rotations, j);
    }
    for (int i = 0; i < problem.num_cameras; ++i) {
      pending_cameras[i] = rotations->cam_from_rig[i]
                               ? std::nullopt
                               : CameraRotation(problem, *rotations, i);
    }
    // Estimates confirmed by two images first (framesets and cameras: `|`
    // does not short-circuit), then those resting on one image, framesets
    // before cameras (see the header).
    const bool assigned_confirmed =
        AssignSupported(pending_framesets, 2, &rotations->rig_from_world) |
        AssignSupported(pending_cameras, 2, &rotations->cam_from_rig);
    if (assigned_confirmed ||
        AssignSupported(pending_framesets, 1, &rotations->rig_from_world) ||
        AssignSupported(pending_cameras, 1, &rotations->cam_from_rig)) {
      continue;
    }
    break;
  }
}

// One sweep: every frameset's rotation from the cameras, then every
// camera's but the base camera's from the framesets, each set at once (the
// estimates of a set do not see one another's updates).
void SweepRotations(const InitProblem& problem, int base_camera,
                    Rotations* rotations) {
  std::vector<std::optional<RotationEstimate>> pending_framesets(
      problem.num_framesets);
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (rotations->rig_from_world[j]) {
      pending_framesets[j] = FramesetRotation(problem, *rotations, j);
    }
  }
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (rotations->rig_from_world[j] && pending_framesets[j]) {
      rotations->rig_from_world[j] = pending_framesets[j]->rotation;
    }
  }
  std::vector<std::optional<RotationEstimate>> pending_cameras(
      problem.num_cameras);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (rotations->cam_from_rig[i] && i != base_camera) {
      pending_cameras[i] = CameraRotation(problem, *rotations, i);
    }
  }
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (rotations->cam_from_rig[i] && i != base_camera && pending_cameras[i]) {
      rotations->cam_from_rig[i] = pending_cameras[i]->rotation;
    }
  }
}

}  // namespace

Rotations AssignRotationsGreedily(const InitProblem& problem, int seed_frameset,
                                  int* base_camera) {
  Rotations rotations = SeedRotations(problem, seed_frameset, base_camera);
  AssignGreedily(problem, &rotations);
  for (int sweep = 0; sweep < kNumRotationSweeps; ++sweep) {
    SweepRotations(problem, *base_camera, &rotations);
  }
  return rotations;
}

}  // namespace rig_init
}  // namespace rig_calibrator
