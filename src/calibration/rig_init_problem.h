// Internal to the rig initialization (rig_initializer.h): the problem its
// pieces share, gathered once from the dataset, and a rig hypothesis.
//
// The pieces, in the order a RANSAC trial uses them:
//   rig_init_rotations.h      greedy back-and-forth assignment of R_P, R_Q
//   rig_init_translations.h   Schur-reduced joint least squares of t_P, t_Q
//   rig_init_determinedness.h which framesets and cameras the images determine
//   rig_init_scoring.h        truncated radial score, image agreement
//   rig_init_refinement.h     the local optimization of eq. 4
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "src/calibration/rig_initializer.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {
namespace rig_init {

// A localized image with what the initializer scores it on.
struct LocalizedImage {
  int camera = -1;
  int frameset = -1;
  Rigid3d cam_from_world;                 // radial: translation.z() = 0
  std::vector<Eigen::Vector2d> points2D;  // centered, scored inlier subset
  std::vector<Eigen::Vector3d> points3D;
  int num_own_inliers = 0;  // scored inliers within the truncation
  // Centroid of the scored map points. Translations are compared there
  // (eq. 3, eq. 4) rather than at the map's origin, whose distance would
  // scale every rotation error into the translations.
  Eigen::Vector3d scene_center = Eigen::Vector3d::Zero();
};

struct InitProblem {
  RigInitializerOptions options;
  int num_cameras = 0;
  int num_framesets = 0;
  int reference_camera = 0;
  int num_rows = 2;  // known rows of each pose: 2 radial, 3 full
  double max_rotation_deviation = 0;  // radians
  int num_threads = 1;
  std::vector<LocalizedImage> images;
  std::vector<std::vector<int>> images_of_frameset;
  std::vector<std::vector<int>> images_of_camera;
};

// A (partial) rig: unassigned cameras and framesets are nullopt.
struct Hypothesis {
  std::vector<std::optional<Rigid3d>> cam_from_rig;    // P_i
  std::vector<std::optional<Rigid3d>> rig_from_world;  // Q_j
};

// A hypothesis with room for every camera and frameset, none assigned.
Hypothesis EmptyHypothesis(const InitProblem& problem);

// Validates the input and gathers the localized images: per image, an
// evenly spread subset of at most kMaxScoredCorrespondences inliers,
// centered on the principal point; images whose own pose explains fewer than
// kMinAgreeingInliers of them are left out. Returns an error message, empty
// on success.
std::string BuildProblem(const RigInitializerOptions& options,
                         const RigDataset& dataset,
                         const RigCalibration& calibration,
                         InitProblem* problem);

}  // namespace rig_init
}  // namespace rig_calibrator
