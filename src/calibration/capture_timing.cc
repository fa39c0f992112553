#include "src/calibration/capture_timing.h"

#include <colmap/estimators/pose.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "src/calibration/calibration_uncertainty.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {
namespace {

// Refines `pose` on the correspondences of `image` with `mask` set (the
// camera's intrinsics held); false when COLMAP's refinement fails.
bool RefineOwnPose(const RigImage& image,
                   const std::vector<Eigen::Vector3d>& points3D,
                   const std::vector<char>& mask, colmap::Camera camera,
                   Rigid3d* pose) {
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> masked_points3D;
  for (size_t k = 0; k < mask.size(); ++k) {
    if (!mask[k]) continue;
    points2D.push_back(image.correspondences[k].point2D);
    masked_points3D.push_back(points3D[k]);
  }
  Eigen::Vector4d qvec = pose->Qvec();
  Eigen::Vector3d tvec = pose->translation;
  colmap::AbsolutePoseRefinementOptions refinement;
  // COLMAP's default gradient tolerance (1) stops a pose that has to move by
  // the rig's motion during the offset (degrees) early; the function
  // tolerance ends it instead.
  refinement.gradient_tolerance = 1e-10;
  refinement.refine_focal_length = false;
  refinement.refine_extra_params = false;
  refinement.print_summary = false;
  const std::vector<char> all(points2D.size(), 1);
  if (!colmap::RefineAbsolutePose(refinement, all, points2D, masked_points3D,
                                  &qvec, &tvec, &camera) ||
      !qvec.allFinite() || !tvec.allFinite()) {
    return false;
  }
  pose->rotation =
      Eigen::Quaterniond(qvec(0), qvec(1), qvec(2), qvec(3)).normalized();
  pose->translation = tvec;
  return true;
}

int CountSet(const std::vector<char>& mask) {
  return static_cast<int>(
      std::count_if(mask.begin(), mask.end(), [](char m) { return m != 0; }));
}

// The image's own cam_from_world (see the top of the header), or nothing
// when it has too few inliers or the refinement fails.
std::optional<Rigid3d> OwnCamFromWorld(const RigDataset& dataset,
                                       const RigCalibration& calibration,
                                       size_t image_index,
                                       const CaptureTimingOptions& options) {
  const RigImage& image = dataset.images[image_index];
  const ImageResult& result = calibration.images[image_index];
  if (!result.used ||
      result.inlier_mask.size() != image.correspondences.size() ||
      !calibration.camera_calibrated[image.camera_index] ||
      !calibration.rig_from_world[image.frameset_index]) {
    return std::nullopt;
  }
  std::vector<Eigen::Vector3d> points3D;
  for (const Correspondence& correspondence : image.correspondences) {
    const auto refined =
        calibration.refined_points3D.find(correspondence.point3D_id);
    points3D.push_back(refined != calibration.refined_points3D.end()
                           ? refined->second
                           : correspondence.point3D);
  }
  const colmap::Camera& camera = calibration.cameras[image.camera_index];
  // A start needs a few final inliers: 6 points over-determine a pose (6
  // degrees of freedom, 2 equations each) twice.
  std::vector<char> mask = result.inlier_mask;
  if (CountSet(mask) < 6) return std::nullopt;
  Rigid3d pose =
      calibration.CamFromWorld(image.camera_index, image.frameset_index);
  if (!RefineOwnPose(image, points3D, mask, camera, &pose)) {
    return std::nullopt;
  }
  // The final inliers are those that fit the synchronized rig: with an
  // offset the adjustment rejects correct matches where the image's pose
  // is far from the rig's, most where the rig moves fastest, and a pose from
  // the rest is pulled toward the rig's (on ring5 with offsets of +-50 ms
  // the offsets came out 2.5 % too small, 3-4 sigma). So the inliers are
  // selected again by the image's own pose, twice.
  for (int round = 0; round < 2; ++round) {
    for (size_t k = 0; k < points3D.size(); ++k) {
      const Eigen::Vector3d in_camera = pose * points3D[k];
      mask[k] = in_camera.z() > 0 &&
                (camera.WorldToImage(in_camera.hnormalized()) -
                 image.correspondences[k].point2D)
                        .norm() < options.inlier_max_error_px;
    }
    if (CountSet(mask) < options.min_inliers ||
        !RefineOwnPose(image, points3D, mask, camera, &pose)) {
      return std::nullopt;
    }
  }
  return pose;
}

}  // namespace

bool OffsetIsSignificant(const CameraTimeOffset& offset,
                         const double rig_angular_speed_rad_s,
                         const double rotation_sigma_rad,
                         const CaptureTimingOptions& options) {
  const double magnitude = std::abs(offset.offset_s);
  if (!offset.observable || !std::isfinite(offset.offset_sigma_s) ||
      magnitude <= options.min_offset_sigmas * offset.offset_sigma_s ||
      magnitude <= options.min_offset_s) {
    return false;
  }
  if (std::isfinite(rotation_sigma_rad) && rotation_sigma_rad > 0) {
    return rig_angular_speed_rad_s * magnitude > rotation_sigma_rad;
  }
  return true;
}

double RigAngularSpeed(const std::vector<double>& frameset_times_s,
                       const RigCalibration& calibration) {
  std::vector<double> speeds;
  for (size_t f = 0; f + 1 < frameset_times_s.size() &&
                     f + 1 < calibration.rig_from_world.size();
       ++f) {
    const std::optional<Rigid3d>& a = calibration.rig_from_world[f];
    const std::optional<Rigid3d>& b = calibration.rig_from_world[f + 1];
    const double dt = frameset_times_s[f + 1] - frameset_times_s[f];
    if (!a || !b || !(dt > 0)) continue;
    speeds.push_back(RotationDifferenceRad(a->rotation, b->rotation) / dt);
  }
  if (speeds.empty()) return 0;
  std::nth_element(speeds.begin(), speeds.begin() + speeds.size() / 2,
                   speeds.end());
  return speeds[speeds.size() / 2];
}

CaptureTiming MeasureCaptureTiming(const RigDataset& dataset,
                                   const RigCalibration& calibration,
                                   const CalibrationUncertainty& uncertainty,
                                   const CaptureTimingOptions& options) {
  CaptureTiming timing;
  const int num_calibrated = static_cast<int>(
      std::count(calibration.camera_calibrated.begin(),
                 calibration.camera_calibrated.end(), true));
  if (dataset.frameset_times_s.empty() || num_calibrated < 2) return timing;
  timing.computed = true;

  TimeOffsetProblem problem;
  problem.frameset_times_s = dataset.frameset_times_s;
  problem.reference_camera = dataset.reference_camera;
  problem.cam_from_world.assign(
      dataset.cameras.size(),
      std::vector<std::optional<Rigid3d>>(dataset.frameset_names.size()));
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const std::optional<Rigid3d> pose =
        OwnCamFromWorld(dataset, calibration, i, options);
    if (!pose) continue;
    const RigImage& image = dataset.images[i];
    problem.cam_from_world[image.camera_index][image.frameset_index] = pose;
    ++timing.num_image_poses;
  }
  timing.rig_angular_speed_rad_s =
      RigAngularSpeed(dataset.frameset_times_s, calibration);
  if (!EstimateTimeOffsets(problem, options.time_offsets, &timing.offsets,
                           &timing.error)) {
    timing.offsets.clear();
    if (timing.error.empty()) timing.error = "the offsets were not estimated";
    return timing;
  }
  timing.significant.assign(timing.offsets.size(), false);
  for (size_t c = 0; c < timing.offsets.size(); ++c) {
    if (static_cast<int>(c) == dataset.reference_camera ||
        !calibration.camera_calibrated[c]) {
      continue;
    }
    double rotation_sigma_rad = 0;
    if (uncertainty.computed && c < uncertainty.cameras.size() &&
        uncertainty.cameras[c].computed) {
      rotation_sigma_rad =
          uncertainty.cameras[c].rotation_stddev_deg * M_PI / 180.0;
    }
    timing.significant[c] =
        OffsetIsSignificant(timing.offsets[c], timing.rig_angular_speed_rad_s,
                            rotation_sigma_rad, options);
  }
  return timing;
}

std::string CaptureTimingLine(const std::vector<std::string>& camera_names,
                              const int reference_camera,
                              const CaptureTiming& timing) {
  std::ostringstream line;
  if (!timing.error.empty()) {
    line << "capture-time offsets not measured: " << timing.error;
    return line.str();
  }
  line << "capture-time offsets against " << camera_names[reference_camera]
       << " (" << timing.num_image_poses << " image poses):";
  bool first = true;
  for (size_t c = 0; c < timing.offsets.size(); ++c) {
    if (static_cast<int>(c) == reference_camera) continue;
    const CameraTimeOffset& offset = timing.offsets[c];
    line << (first ? " " : ", ") << camera_names[c];
    first = false;
    if (!offset.observable) {
      line << " not observable (" << offset.diagnosis << ")";
      continue;
    }
    line << std::showpos << std::fixed << std::setprecision(2) << " "
         << offset.offset_s * 1e3 << std::noshowpos << " +- "
         << offset.offset_sigma_s * 1e3 << " ms" << std::defaultfloat;
    if (timing.significant[c]) line << " (unsynchronized)";
  }
  return line.str();
}

}  // namespace rig_calibrator
