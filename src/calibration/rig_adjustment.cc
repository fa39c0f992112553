#include "src/calibration/rig_adjustment.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "src/geometry/rig_reprojection_cost.h"
#include "src/geometry/timed_rig_reprojection_cost.h"

namespace rig_calibrator {

RigAdjustment::RigAdjustment(const FinalBundleAdjustmentOptions& options,
                             const RigDataset& dataset,
                             const RigCalibration& calibration)
    : options_(options),
      dataset_(dataset),
      cameras_(calibration.cameras),
      loss_(std::make_unique<ceres::CauchyLoss>(options.loss_scale_px)),
      pose_manifold_(std::make_unique<RigPoseManifold>()) {
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
        observations_.emplace_back();
        observations_.back().image = static_cast<int>(i);
        observations_.back().correspondence = static_cast<int>(k);
      }
    }
  }
  num_given_inliers_ = observations_.size();
  if (options.HasTimeModel()) {
    const size_t num_cameras = dataset.cameras.size();
    time_offsets_ = options.initial_time_offsets_s.empty()
                        ? std::vector<double>(num_cameras, 0.0)
                        : options.initial_time_offsets_s;
    line_delays_ = options.initial_line_delays_s.empty()
                       ? std::vector<double>(num_cameras, 0.0)
                       : options.initial_line_delays_s;
    frameset_motions_.resize(rig_from_world_.size());
    frameset_translations_.assign(rig_from_world_.size(),
                                  TranslationDerivatives::Zero());
    if (calibration.rig_translation_derivatives.size() ==
        rig_from_world_.size()) {
      frameset_translations_ = calibration.rig_translation_derivatives;
      translations_started_ = true;
    }
    UpdateFramesetMotions();
  }
  // Without use_map_observations the map images are still evaluated after
  // the last solve, so that their observations that no longer fit the
  // refined points are rejected (RejectMapOutliers).
  if (options.refine_points && !dataset.map_images.empty()) {
    map_cameras_ = dataset.map_cameras;
    for (const MapImage& image : dataset.map_images) {
      map_cam_from_world_.push_back(ToPoseParams(image.cam_from_world));
      map_rejected_.emplace_back(image.observations.size(), 0);
    }
    map_points_ = dataset.map_points3D;
  }
}

const MapObservation& RigAdjustment::MapObservationOf(
    const MapObservationRef& observation) const {
  return dataset_.map_images[observation.image]
      .observations[observation.observation];
}

int RigAdjustment::MapCameraSlot(const MapObservationRef& observation) const {
  return static_cast<int>(cameras_.size()) +
         dataset_.map_images[observation.image].camera_index;
}

std::vector<RigAdjustment::MapObservationRef>
RigAdjustment::MapObservationsInProblem() const {
  if (!options_.use_map_observations) {
    return {};
  }
  return MapObservationsOfRefinedPoints();
}

std::vector<RigAdjustment::MapObservationRef>
RigAdjustment::MapObservationsOfRefinedPoints() const {
  std::vector<MapObservationRef> in_problem;
  for (size_t i = 0; i < map_rejected_.size(); ++i) {
    const MapImage& image = dataset_.map_images[i];
    for (size_t k = 0; k < image.observations.size(); ++k) {
      if (!map_rejected_[i][k] &&
          IsPointRefined(image.observations[k].point3D_id)) {
        in_problem.push_back({static_cast<int>(i), static_cast<int>(k)});
      }
    }
  }
  return in_problem;
}

size_t RigAdjustment::NumMapObservationsInProblem() const {
  return MapObservationsInProblem().size();
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
  Eigen::Vector3d point_in_cam;
  if (time_offsets_.empty()) {
    const Rigid3d cam_from_world =
        FromPoseParams(cam_from_rig_[image.camera_index]) *
        FromPoseParams(rig_from_world_[image.frameset_index]);
    point_in_cam = cam_from_world * PointOf(observation);
  } else {
    // The rig pose at the observation's own instant (the time model).
    const double tau = CaptureTimeOfRow(time_offsets_[image.camera_index],
                                        line_delays_[image.camera_index],
                                        correspondence.point2D.y());
    Eigen::Vector3d point_in_rig;
    WorldToRigAtOffset(rig_from_world_[image.frameset_index].data(),
                       PointOf(observation).data(),
                       frameset_motions_[image.frameset_index],
                       frameset_translations_[image.frameset_index].data(),
                       tau, point_in_rig.data());
    point_in_cam = FromPoseParams(cam_from_rig_[image.camera_index]) *
                   point_in_rig;
  }
  ObservationError error;
  error.depth = point_in_cam.z();
  if (error.depth > 0) {
    error.residual =
        cameras_[image.camera_index].WorldToImage(point_in_cam.hnormalized()) -
        correspondence.point2D;
  }
  return error;
}

RigAdjustment::ObservationError RigAdjustment::Evaluate(
    const MapObservationRef& observation) const {
  const MapImage& image = dataset_.map_images[observation.image];
  const MapObservation& map_observation = MapObservationOf(observation);
  const Eigen::Vector3d point_in_cam =
      FromPoseParams(map_cam_from_world_[observation.image]) *
      PointOf(map_observation.point3D_id);
  ObservationError error;
  error.depth = point_in_cam.z();
  if (error.depth > 0) {
    error.residual = map_cameras_[image.camera_index].WorldToImage(
                         point_in_cam.hnormalized()) -
                     map_observation.point2D;
  }
  return error;
}

double RigAdjustment::MapRmsError() {
  if (!points_selected_ && options_.refine_points) {
    SelectRefinedPoints();
  }
  const std::vector<MapObservationRef> in_problem = MapObservationsInProblem();
  double sum = 0;
  for (const auto& [slot, error] :
       EvaluateWithSlots(/*with_rig_observations=*/false, in_problem)) {
    sum += error.residual.squaredNorm();
  }
  return in_problem.empty() ? 0 : std::sqrt(sum / in_problem.size());
}

int RigAdjustment::NumThreads() const {
  return options_.num_threads > 0 ? options_.num_threads
                                  : omp_get_max_threads();
}

RigAdjustment::ObservationErrors RigAdjustment::EvaluateObservations() const {
  ObservationErrors errors(observations_.size());
  const int64_t num_observations = static_cast<int64_t>(observations_.size());
#pragma omp parallel for schedule(static) num_threads(NumThreads())
  for (int64_t k = 0; k < num_observations; ++k) {
    errors[k] = Evaluate(observations_[k]);
  }
  return errors;
}

RigAdjustment::SlotErrors RigAdjustment::EvaluateWithSlots(
    bool with_rig_observations,
    const std::vector<MapObservationRef>& map_observations) const {
  const int64_t num_rig =
      with_rig_observations ? static_cast<int64_t>(observations_.size()) : 0;
  const int64_t num_all =
      num_rig + static_cast<int64_t>(map_observations.size());
  SlotErrors errors(num_all);
#pragma omp parallel for schedule(static) num_threads(NumThreads())
  for (int64_t k = 0; k < num_all; ++k) {
    if (k < num_rig) {
      errors[k] = {CameraOf(observations_[k]), Evaluate(observations_[k])};
    } else {
      const MapObservationRef& observation = map_observations[k - num_rig];
      errors[k] = {MapCameraSlot(observation), Evaluate(observation)};
    }
  }
  return errors;
}

double RigAdjustment::RmsError() const {
  double sum = 0;
  for (const ObservationError& error : EvaluateObservations()) {
    sum += error.residual.squaredNorm();
  }
  return observations_.empty() ? 0 : std::sqrt(sum / observations_.size());
}

Eigen::Vector3d* RigAdjustment::RefinedPoint(int64_t point3D_id) {
  const auto it = refined_point_index_.find(point3D_id);
  return it != refined_point_index_.end() ? &refined_points_[it->second]
                                          : nullptr;
}

const Eigen::Vector3d* RigAdjustment::RefinedPoint(int64_t point3D_id) const {
  const auto it = refined_point_index_.find(point3D_id);
  return it != refined_point_index_.end() ? &refined_points_[it->second]
                                          : nullptr;
}

const Eigen::Vector3d& RigAdjustment::PointOf(int64_t point3D_id) const {
  const Eigen::Vector3d* refined = RefinedPoint(point3D_id);
  return refined != nullptr ? *refined : map_points_.at(point3D_id);
}

bool RigAdjustment::IsPointRefined(int64_t point3D_id) const {
  return point3D_id >= 0 && refined_point_index_.count(point3D_id) > 0;
}

const Eigen::Vector3d& RigAdjustment::PointOf(
    const Observation& observation) const {
  return observation.refined_slot >= 0
             ? refined_points_[observation.refined_slot]
             : CorrespondenceOf(observation).point3D;
}

void RigAdjustment::SelectRefinedPoints() {
  const bool first_selection = !points_selected_;
  points_selected_ = true;
  selection_current_ = true;
  // The rig observations' points, sorted by id (runs of one point), with the
  // observation: counting by sorting, not hashing, 945 000 observations
  // at 500 framesets x 10 cameras.
  std::vector<std::pair<int64_t, size_t>> rig_ids;
  rig_ids.reserve(observations_.size());
  for (size_t k = 0; k < observations_.size(); ++k) {
    observations_[k].refined_slot = -1;
    const int64_t point3D_id = CorrespondenceOf(observations_[k]).point3D_id;
    if (point3D_id >= 0) rig_ids.emplace_back(point3D_id, k);
  }
  std::sort(rig_ids.begin(), rig_ids.end());
  const auto seen_by_rig = [&](int64_t point3D_id) {
    const auto it = std::lower_bound(rig_ids.begin(), rig_ids.end(), point3D_id,
                                     [](const std::pair<int64_t, size_t>& a,
                                        int64_t id) { return a.first < id; });
    return it != rig_ids.end() && it->first == point3D_id;
  };
  // Observations only ever leave: the first selection sees every point.
  if (first_selection) {
    for (size_t k = 0; k < rig_ids.size(); ++k) {
      if (k == 0 || rig_ids[k].first != rig_ids[k - 1].first) {
        map_points_.try_emplace(
            rig_ids[k].first,
            CorrespondenceOf(observations_[rig_ids[k].second]).point3D);
      }
    }
  }
  // The map images' current observations of points: all with refine_map,
  // else those of points the rig images see.
  std::vector<int64_t> map_ids;
  for (size_t i = 0; options_.use_map_observations && i < map_rejected_.size();
       ++i) {
    const MapImage& image = dataset_.map_images[i];
    for (size_t k = 0; k < image.observations.size(); ++k) {
      const int64_t point3D_id = image.observations[k].point3D_id;
      if (!map_rejected_[i][k] &&
          (options_.refine_map || seen_by_rig(point3D_id))) {
        map_ids.push_back(point3D_id);
      }
    }
  }
  std::sort(map_ids.begin(), map_ids.end());
  // Points with two observations or more, in increasing id: a merge of the
  // two sorted lists.
  std::vector<int64_t> refined_ids;
  for (size_t i = 0, j = 0; i < rig_ids.size() || j < map_ids.size();) {
    const int64_t point3D_id =
        j == map_ids.size() ||
                (i < rig_ids.size() && rig_ids[i].first < map_ids[j])
            ? rig_ids[i].first
            : map_ids[j];
    int count = 0;
    for (; i < rig_ids.size() && rig_ids[i].first == point3D_id; ++i) ++count;
    for (; j < map_ids.size() && map_ids[j] == point3D_id; ++j) ++count;
    if (count >= 2) refined_ids.push_back(point3D_id);
  }
  if (solver_ != nullptr) {
    HoldPointsNoLongerRefined(refined_ids, rig_ids);
    return;
  }
  std::vector<Eigen::Vector3d> refined_points;
  refined_points.reserve(refined_ids.size());
  std::unordered_map<int64_t, size_t> refined_point_index;
  refined_point_index.reserve(refined_ids.size());
  for (const int64_t point3D_id : refined_ids) {
    const Eigen::Vector3d* refined = RefinedPoint(point3D_id);
    refined_point_index[point3D_id] = refined_points.size();
    refined_points.push_back(refined != nullptr ? *refined
                                                : map_points_.at(point3D_id));
  }
  refined_points_ = std::move(refined_points);
  refined_point_index_ = std::move(refined_point_index);
  // The rig observations' slots: both lists are sorted by id.
  size_t slot = 0;
  for (const auto& [point3D_id, observation] : rig_ids) {
    while (slot < refined_ids.size() && refined_ids[slot] < point3D_id) ++slot;
    if (slot < refined_ids.size() && refined_ids[slot] == point3D_id) {
      observations_[observation].refined_slot = static_cast<int64_t>(slot);
    }
  }
}

// With the problem built, the points keep their slots (the solver holds
// their addresses): a point that is no longer refined goes back to its map
// position, held by the solver, and leaves refined_point_index_. Observations
// only ever leave, so no point becomes refined again.
void RigAdjustment::HoldPointsNoLongerRefined(
    const std::vector<int64_t>& refined_ids,
    const std::vector<std::pair<int64_t, size_t>>& rig_ids) {
  for (auto it = refined_point_index_.begin();
       it != refined_point_index_.end();) {
    if (std::binary_search(refined_ids.begin(), refined_ids.end(), it->first)) {
      ++it;
      continue;
    }
    Eigen::Vector3d& point = refined_points_[it->second];
    point = map_points_.at(it->first);
    solver_->SetPointHeld(point.data(), true);
    it = refined_point_index_.erase(it);
  }
  for (size_t k = 0; k < rig_ids.size();) {
    const auto it = refined_point_index_.find(rig_ids[k].first);
    const int64_t slot = it != refined_point_index_.end()
                             ? static_cast<int64_t>(it->second)
                             : -1;
    for (const int64_t point3D_id = rig_ids[k].first;
         k < rig_ids.size() && rig_ids[k].first == point3D_id; ++k) {
      observations_[rig_ids[k].second].refined_slot = slot;
    }
  }
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
  calibration->rig_translation_derivatives = frameset_translations_;
  calibration->frameset_motions_without_own_pose = frameset_without_own_pose_;
  for (size_t i = 0; i < dataset_.images.size(); ++i) {
    ImageResult& result = calibration->images[i];
    result.inlier_mask.assign(dataset_.images[i].correspondences.size(), 0);
    result.num_inliers = 0;
    result.rms_px = 0;
  }
  // The errors on all threads, summed per image in observation order.
  const ObservationErrors errors = EvaluateObservations();
  std::vector<double> sum_squared_error(dataset_.images.size(), 0);
  for (size_t k = 0; k < observations_.size(); ++k) {
    const Observation& observation = observations_[k];
    ImageResult& result = calibration->images[observation.image];
    result.inlier_mask[observation.correspondence] = 1;
    ++result.num_inliers;
    sum_squared_error[observation.image] += errors[k].residual.squaredNorm();
  }
  for (size_t i = 0; i < dataset_.images.size(); ++i) {
    ImageResult& result = calibration->images[i];
    result.used = result.num_inliers > 0;
    if (result.used) {
      result.rms_px = std::sqrt(sum_squared_error[i] / result.num_inliers);
    }
  }
  calibration->refined_points3D.clear();
  for (const auto& [point3D_id, slot] : refined_point_index_) {
    calibration->refined_points3D[point3D_id] = refined_points_[slot];
  }
  calibration->map_cameras.clear();
  calibration->map_cam_from_world.clear();
  calibration->map_observation_rejected.clear();
  if (!dataset_.map_images.empty()) {
    calibration->map_cameras =
        map_cameras_.empty() ? dataset_.map_cameras : map_cameras_;
    for (size_t i = 0; i < dataset_.map_images.size(); ++i) {
      const MapImage& image = dataset_.map_images[i];
      calibration->map_cam_from_world.push_back(
          map_cam_from_world_.empty() ? image.cam_from_world
                                      : FromPoseParams(map_cam_from_world_[i]));
      calibration->map_observation_rejected.push_back(
          map_rejected_.empty()
              ? std::vector<char>(image.observations.size(), 0)
              : map_rejected_[i]);
    }
  }
}

}  // namespace rig_calibrator
