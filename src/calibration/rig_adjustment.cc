#include "src/calibration/rig_adjustment.h"

#include <cmath>

namespace rig_calibrator {

PoseParams ToPoseParams(const Rigid3d& pose) {
  return {pose.rotation.w(),   pose.rotation.x(),    pose.rotation.y(),
          pose.rotation.z(),   pose.translation.x(), pose.translation.y(),
          pose.translation.z()};
}

Rigid3d FromPoseParams(const PoseParams& params) {
  return Rigid3d(Eigen::Quaterniond(params[0], params[1], params[2], params[3]),
                 Eigen::Vector3d(params[4], params[5], params[6]));
}

RigAdjustment::RigAdjustment(const FinalBundleAdjustmentOptions& options,
                             const RigDataset& dataset,
                             const RigCalibration& calibration)
    : options_(options),
      dataset_(dataset),
      cameras_(calibration.cameras),
      loss_(std::make_unique<ceres::CauchyLoss>(options.loss_scale_px)),
      pose_manifold_(
          std::make_unique<ceres::ProductManifold<
              ceres::QuaternionManifold, ceres::EuclideanManifold<3>>>()) {
  for (const Rigid3d& pose : calibration.cam_from_rig) {
    cam_from_rig_.push_back(ToPoseParams(pose));
  }
  for (const std::optional<Rigid3d>& pose : calibration.rig_from_world) {
    rig_from_world_.push_back(pose ? ToPoseParams(*pose) : PoseParams{});
    has_rig_pose_.push_back(pose.has_value());
  }
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    if (!calibration.camera_calibrated[image.camera_index] ||
        !calibration.rig_from_world[image.frameset_index]) {
      continue;
    }
    const std::vector<char>& mask = calibration.images[i].inlier_mask;
    for (size_t k = 0; k < mask.size(); ++k) {
      if (mask[k]) {
        observations_.push_back({static_cast<int>(i), static_cast<int>(k)});
      }
    }
  }
  num_given_inliers_ = observations_.size();
}

const Correspondence& RigAdjustment::CorrespondenceOf(
    const Observation& observation) const {
  return dataset_.images[observation.image]
      .correspondences[observation.correspondence];
}

int RigAdjustment::CameraOf(const Observation& observation) const {
  return dataset_.images[observation.image].camera_index;
}

RigAdjustment::ObservationError RigAdjustment::Evaluate(
    const Observation& observation) const {
  const RigImage& image = dataset_.images[observation.image];
  const Correspondence& correspondence = CorrespondenceOf(observation);
  const Rigid3d cam_from_world =
      FromPoseParams(cam_from_rig_[image.camera_index]) *
      FromPoseParams(rig_from_world_[image.frameset_index]);
  const Eigen::Vector3d point_in_cam = cam_from_world * PointOf(correspondence);
  ObservationError error;
  error.depth = point_in_cam.z();
  if (error.depth > 0) {
    error.residual =
        cameras_[image.camera_index].WorldToImage(point_in_cam.hnormalized()) -
        correspondence.point2D;
  }
  return error;
}

double RigAdjustment::RmsError() const {
  double sum = 0;
  for (const Observation& observation : observations_) {
    sum += Evaluate(observation).residual.squaredNorm();
  }
  return observations_.empty() ? 0 : std::sqrt(sum / observations_.size());
}

const Eigen::Vector3d& RigAdjustment::PointOf(
    const Correspondence& correspondence) const {
  if (correspondence.point3D_id >= 0) {
    const auto it = refined_points_.find(correspondence.point3D_id);
    if (it != refined_points_.end()) {
      return it->second;
    }
  }
  return correspondence.point3D;
}

bool RigAdjustment::IsPointRefined(const Correspondence& correspondence) const {
  return correspondence.point3D_id >= 0 &&
         refined_points_.count(correspondence.point3D_id) > 0;
}

void RigAdjustment::SelectRefinedPoints() {
  std::unordered_map<int64_t, int> num_observations;
  for (const Observation& observation : observations_) {
    const Correspondence& correspondence = CorrespondenceOf(observation);
    if (correspondence.point3D_id >= 0) {
      ++num_observations[correspondence.point3D_id];
      map_points_.emplace(correspondence.point3D_id, correspondence.point3D);
    }
  }
  std::unordered_map<int64_t, Eigen::Vector3d> refined_points;
  for (const auto& [point3D_id, count] : num_observations) {
    if (count >= 2) {
      const auto it = refined_points_.find(point3D_id);
      refined_points[point3D_id] =
          it != refined_points_.end() ? it->second : map_points_.at(point3D_id);
    }
  }
  refined_points_ = std::move(refined_points);
}

void RigAdjustment::WriteTo(RigCalibration* calibration) const {
  calibration->cameras = cameras_;
  for (size_t camera = 0; camera < cameras_.size(); ++camera) {
    calibration->cam_from_rig[camera] = FromPoseParams(cam_from_rig_[camera]);
  }
  for (size_t frameset = 0; frameset < rig_from_world_.size(); ++frameset) {
    if (has_rig_pose_[frameset]) {
      calibration->rig_from_world[frameset] =
          FromPoseParams(rig_from_world_[frameset]);
    }
  }
  for (size_t i = 0; i < dataset_.images.size(); ++i) {
    ImageResult& result = calibration->images[i];
    result.inlier_mask.assign(dataset_.images[i].correspondences.size(), 0);
    result.num_inliers = 0;
    result.rms_px = 0;
  }
  std::vector<double> sum_squared_error(dataset_.images.size(), 0);
  for (const Observation& observation : observations_) {
    ImageResult& result = calibration->images[observation.image];
    result.inlier_mask[observation.correspondence] = 1;
    ++result.num_inliers;
    sum_squared_error[observation.image] +=
        Evaluate(observation).residual.squaredNorm();
  }
  for (size_t i = 0; i < dataset_.images.size(); ++i) {
    ImageResult& result = calibration->images[i];
    result.used = result.num_inliers > 0;
    if (result.used) {
      result.rms_px = std::sqrt(sum_squared_error[i] / result.num_inliers);
    }
  }
  calibration->refined_points3D.clear();
  for (const auto& [point3D_id, point] : refined_points_) {
    calibration->refined_points3D[point3D_id] = point;
  }
}

}  // namespace rig_calibrator
