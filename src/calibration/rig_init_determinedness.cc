#include "src/calibration/rig_init_determinedness.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "src/calibration/principal_axes.h"
#include "src/calibration/rig_init_translations.h"

namespace rig_calibrator {
namespace rig_init {
namespace {

// Whether a frameset's images (parts.images) determine its rig translation.
bool FramesetDetermined(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_from_rig,
    const std::vector<char>& images, int frameset) {
  std::vector<Eigen::Vector3d> axes;
  for (const int index : problem.images_of_frameset[frameset]) {
    if (images[index]) {
      axes.push_back(cam_from_rig[problem.images[index].camera]
                         ->toRotationMatrix()
                         .row(2)
                         .transpose());
    }
  }
  return problem.num_rows == 2 ? AxesDetermineTranslation(axes) : !axes.empty();
}

// Whether the images of `parts` determine all camera translations relative
// to the anchor: no eigenvalue of the unweighted reduced matrix (gauge
// fixed) below half the determinedness threshold of one frameset,
// AxisEigenvalueOfAngle(kMinDeterminingAxisAngleDeg) / 2. The matrix is
// dimensionless; one frameset with two cameras at that angle contributes
// about the threshold.
bool TranslationsDetermined(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    const DeterminedParts& parts, int anchor) {
  const ReducedTranslationSystem system = BuildReducedTranslationSystem(
      problem, cam_rotations, rig_rotations, parts,
      std::vector<double>(problem.images.size(), 1.0), anchor);
  return system.reduced.rows() == 0 ||
         Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(system.reduced,
                                                        Eigen::EigenvaluesOnly)
                 .eigenvalues()(0) >=
             0.5 * AxisEigenvalueOfAngle(kMinDeterminingAxisAngleDeg);
}

// The cameras of `parts` that join the anchor one by one (see
// FindTranslationDeterminedParts), until none does.
std::vector<char> GrowFromAnchor(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    const DeterminedParts& parts, int anchor) {
  std::vector<char> joined(problem.num_cameras, 0);
  joined[anchor] = 1;
  bool grown = true;
  while (grown) {
    grown = false;
    for (int i = 0; i < problem.num_cameras; ++i) {
      if (joined[i] || !parts.cameras[i]) continue;
      std::vector<char> subset_images = parts.images;
      for (size_t k = 0; k < problem.images.size(); ++k) {
        const int camera = problem.images[k].camera;
        subset_images[k] = subset_images[k] && (joined[camera] || camera == i);
      }
      const DeterminedParts subset =
          FindDeterminedParts(problem, cam_rotations, subset_images, 1);
      if (subset.cameras[i] && subset.cameras[anchor] &&
          TranslationsDetermined(problem, cam_rotations, rig_rotations, subset,
                                 anchor)) {
        joined[i] = 1;
        grown = true;
      }
    }
  }
  return joined;
}

}  // namespace

DeterminedParts FindDeterminedParts(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_from_rig,
    const std::vector<char>& usable_images, int min_images_per_camera) {
  DeterminedParts parts;
  parts.images = usable_images;
  for (size_t k = 0; k < problem.images.size(); ++k) {
    parts.images[k] = parts.images[k] && cam_from_rig[problem.images[k].camera];
  }
  bool changed = true;
  while (changed) {
    changed = false;
    parts.framesets.assign(problem.num_framesets, 0);
    for (int j = 0; j < problem.num_framesets; ++j) {
      parts.framesets[j] =
          FramesetDetermined(problem, cam_from_rig, parts.images, j);
    }
    std::vector<int> num_camera_images(problem.num_cameras, 0);
    for (size_t k = 0; k < problem.images.size(); ++k) {
      if (parts.images[k] && parts.framesets[problem.images[k].frameset]) {
        ++num_camera_images[problem.images[k].camera];
      }
    }
    parts.cameras.assign(problem.num_cameras, 0);
    for (int i = 0; i < problem.num_cameras; ++i) {
      parts.cameras[i] = num_camera_images[i] >= min_images_per_camera;
    }
    for (size_t k = 0; k < problem.images.size(); ++k) {
      const LocalizedImage& image = problem.images[k];
      if (parts.images[k] &&
          !(parts.framesets[image.frameset] && parts.cameras[image.camera])) {
        parts.images[k] = 0;
        changed = true;
      }
    }
  }
  return parts;
}

DeterminedParts FindTranslationDeterminedParts(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    std::vector<char> usable_images, int min_images_per_camera,
    int preferred_anchor, int* anchor) {
  while (true) {
    const DeterminedParts parts = FindDeterminedParts(
        problem, cam_rotations, usable_images, min_images_per_camera);
    *anchor = parts.cameras[preferred_anchor]
                  ? preferred_anchor
                  : std::find(parts.cameras.begin(), parts.cameras.end(), 1) -
                        parts.cameras.begin();
    if (*anchor == problem.num_cameras) return parts;
    const std::vector<char> joined =
        GrowFromAnchor(problem, cam_rotations, rig_rotations, parts, *anchor);
    if (joined == parts.cameras) return parts;
    for (size_t k = 0; k < problem.images.size(); ++k) {
      if (!joined[problem.images[k].camera]) usable_images[k] = 0;
    }
  }
}

}  // namespace rig_init
}  // namespace rig_calibrator
