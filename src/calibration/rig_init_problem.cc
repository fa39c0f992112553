#include "src/calibration/rig_init_problem.h"

#include <colmap/util/math.h>
#include <colmap/util/threading.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include "src/calibration/rig_init_scoring.h"

namespace rig_calibrator {
namespace rig_init {
namespace {

// Scoring never needs every correspondence: an evenly spread subset of each
// image's inliers is enough to tell a right rig from a wrong one.
constexpr int kMaxScoredCorrespondences = 64;

// The options and the dataset's sizes; an error message, empty if valid.
std::string CheckOptionsAndSizes(const RigInitializerOptions& options,
                                 const RigDataset& dataset,
                                 const RigCalibration& calibration) {
  const int num_cameras = dataset.cameras.size();
  std::ostringstream error;
  if (num_cameras == 0) return "the dataset has no cameras";
  if (dataset.reference_camera < 0 || dataset.reference_camera >= num_cameras) {
    error << "reference camera index " << dataset.reference_camera
          << " is not one of the " << num_cameras << " cameras";
    return error.str();
  }
  if (!(options.max_radial_error_px > 0) || !(options.loss_scale > 0) ||
      !(options.max_rotation_deviation_deg > 0) ||
      !(options.translation_weight >= 0) || !(options.confidence > 0) ||
      !(options.confidence < 1) || options.max_num_trials < 1) {
    return "invalid options: max_radial_error_px, loss_scale and "
           "max_rotation_deviation_deg must be positive, translation_weight "
           "non-negative, confidence in (0, 1), "
           "max_num_trials >= 1";
  }
  if (calibration.images.size() != dataset.images.size()) {
    error << "calibration has " << calibration.images.size()
          << " image results for " << dataset.images.size() << " images";
    return error.str();
  }
  for (const RigCamera& camera : dataset.cameras) {
    if (!camera.camera.VerifyParams()) {
      return "camera " + camera.name + " has no valid model parameters";
    }
  }
  return "";
}

// An image's indices and inlier mask; an error message, empty if valid.
std::string CheckImage(const RigImage& rig_image, const ImageResult& result,
                       const InitProblem& problem) {
  std::ostringstream error;
  if (rig_image.camera_index < 0 ||
      rig_image.camera_index >= problem.num_cameras ||
      rig_image.frameset_index < 0 ||
      rig_image.frameset_index >= problem.num_framesets) {
    error << "image " << rig_image.name << " has camera index "
          << rig_image.camera_index << " and frameset index "
          << rig_image.frameset_index << ", out of range";
    return error.str();
  }
  if (!result.inlier_mask.empty() &&
      result.inlier_mask.size() != rig_image.correspondences.size()) {
    error << "image " << rig_image.name << " has an inlier mask of size "
          << result.inlier_mask.size() << " for "
          << rig_image.correspondences.size() << " correspondences";
    return error.str();
  }
  return "";
}

// A localized image's pose, scored inlier subset and scene center.
LocalizedImage MakeLocalizedImage(const RigImage& rig_image,
                                  const ImageResult& result,
                                  const colmap::Camera& camera,
                                  const RigInitializerOptions& options) {
  LocalizedImage image;
  image.camera = rig_image.camera_index;
  image.frameset = rig_image.frameset_index;
  image.cam_from_world = *result.single_image_cam_from_world;
  if (options.radial) image.cam_from_world.translation.z() = 0;

  std::vector<int> inliers;
  for (size_t c = 0; c < result.inlier_mask.size(); ++c) {
    if (result.inlier_mask[c]) inliers.push_back(c);
  }
  const int num_scored =
      std::min<int>(inliers.size(), kMaxScoredCorrespondences);
  const Eigen::Vector2d principal_point(camera.PrincipalPointX(),
                                        camera.PrincipalPointY());
  for (int s = 0; s < num_scored; ++s) {
    const Correspondence& correspondence =
        rig_image.correspondences[inliers[s * inliers.size() / num_scored]];
    image.points2D.push_back(correspondence.point2D - principal_point);
    image.points3D.push_back(correspondence.point3D);
  }
  image.num_own_inliers =
      FitImage(image.cam_from_world, image, options.max_radial_error_px)
          .num_within;
  for (const Eigen::Vector3d& point : image.points3D) {
    image.scene_center += point / image.points3D.size();
  }
  return image;
}

}  // namespace

Hypothesis EmptyHypothesis(const InitProblem& problem) {
  Hypothesis hypothesis;
  hypothesis.cam_from_rig.resize(problem.num_cameras);
  hypothesis.rig_from_world.resize(problem.num_framesets);
  return hypothesis;
}

std::string BuildProblem(const RigInitializerOptions& options,
                         const RigDataset& dataset,
                         const RigCalibration& calibration,
                         InitProblem* problem) {
  problem->options = options;
  problem->num_cameras = dataset.cameras.size();
  problem->num_framesets = dataset.frameset_names.size();
  problem->reference_camera = dataset.reference_camera;
  problem->num_rows = options.radial ? 2 : 3;
  problem->max_rotation_deviation =
      colmap::DegToRad(options.max_rotation_deviation_deg);
  problem->num_threads = colmap::GetEffectiveNumThreads(options.num_threads);
  problem->images_of_frameset.assign(problem->num_framesets, {});
  problem->images_of_camera.assign(problem->num_cameras, {});

  const std::string invalid =
      CheckOptionsAndSizes(options, dataset, calibration);
  if (!invalid.empty()) return invalid;

  std::map<std::pair<int, int>, int> image_of_slot;
  for (size_t k = 0; k < dataset.images.size(); ++k) {
    const RigImage& rig_image = dataset.images[k];
    const ImageResult& result = calibration.images[k];
    const std::string invalid_image = CheckImage(rig_image, result, *problem);
    if (!invalid_image.empty()) return invalid_image;
    if (!result.single_image_cam_from_world) continue;
    const auto [slot, inserted] = image_of_slot.emplace(
        std::make_pair(rig_image.camera_index, rig_image.frameset_index), k);
    if (!inserted) {
      std::ostringstream error;
      error << "images " << dataset.images[slot->second].name << " and "
            << rig_image.name << " are both localized images of camera "
            << dataset.cameras[rig_image.camera_index].name << " in frameset "
            << rig_image.frameset_index;
      return error.str();
    }
    const Rigid3d& pose = *result.single_image_cam_from_world;
    if (!pose.rotation.coeffs().allFinite() ||
        !pose.translation.head(problem->num_rows).allFinite()) {
      return "image " + rig_image.name + " has a non-finite pose";
    }

    LocalizedImage image = MakeLocalizedImage(
        rig_image, result, dataset.cameras[rig_image.camera_index].camera,
        options);
    // A pose that does not explain its own inliers can agree with nothing.
    if (image.num_own_inliers < kMinAgreeingInliers) continue;
    problem->images_of_frameset[image.frameset].push_back(
        problem->images.size());
    problem->images_of_camera[image.camera].push_back(problem->images.size());
    problem->images.push_back(std::move(image));
  }
  return "";
}

}  // namespace rig_init
}  // namespace rig_calibrator
