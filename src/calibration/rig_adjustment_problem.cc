// The problem of the final bundle adjustment: one RigReprojectionCost per
// observation (with a time model a TimedRigReprojectionCost, whose extra
// blocks are the camera's offset and line delay and the frameset's
// velocity and acceleration, which have a prior) (a map image's: its
// cam_from_world as the "rig" pose, a constant identity cam_from_rig), the
// blocks that are refined, held or partly held, and its solve by the bundle
// solver (bundle_solver.h, the options' backend) with the refined points
// eliminated.
#include <glog/logging.h>

#include "src/calibration/rig_adjustment.h"
#include "src/geometry/rig_reprojection_cost.h"
#include "src/geometry/timed_rig_reprojection_cost.h"

namespace rig_calibrator {

bool RigAdjustment::Solve(double function_tolerance,
                          BundleSolverSummary* summary) {
  if (options_.HasTimeModel()) {
    // The motion at the current rig poses, held during the solve. An
    // observation that it puts behind its camera (or out of the depth
    // range) leaves: the solve cannot start from a residual it cannot
    // evaluate (a wide fisheye's point near 90 degrees off axis, when the
    // motion over 40 ms changed with the poses; on a 15 Hz car this failed
    // the time model's whole adjustment).
    UpdateFramesetMotions();
    RejectOutliers(/*prune_residuals=*/false);
  }
  if (options_.refine_points && !selection_current_) {
    SelectRefinedPoints();
  }
  if (solver_ == nullptr) {
    BundleSolverOptions solver_options;
    solver_options.max_num_iterations = options_.max_num_iterations;
    // Exact data converges quadratically; a parameter tolerance relative to
    // the whole parameter vector (dominated by the focal lengths) of Ceres'
    // default 1e-8 would stop a few digits short.
    solver_options.parameter_tolerance = 1e-12;
    solver_options.num_threads = options_.num_threads;
    solver_options.print_progress = options_.print_progress;
    solver_ = MakeBundleSolver(options_.bundle_solver, solver_options);
    const std::vector<MapObservationRef> map_observations =
        MapObservationsInProblem();
    solver_->Reserve(observations_.size() + map_observations.size(),
                     refined_points_.size());
    AddParameterBlocks(map_observations);
    AddResidualBlocks(map_observations);
  } else {
    UpdateResidualBlocks();
  }
  solver_->SetFunctionTolerance(function_tolerance);
  VLOG(1) << "Final bundle adjustment: "
          << observations_.size() + NumMapObservationsInProblem()
          << " observations";
  solver_->Solve(summary);
  VLOG(1) << summary->BriefReport() << "; " << summary->seconds
          << " s: structure " << summary->structure_seconds << " s, evaluation "
          << summary->evaluation_seconds << " s, reduced system "
          << summary->schur_seconds << " s, factorization "
          << summary->factorization_seconds << " s; reduced system "
          << summary->reduced_system_size << " unknowns, "
          << summary->num_points << " points";
  if (!summary->IsSolutionUsable()) {
    LOG(ERROR) << "Final bundle adjustment failed: " << summary->message;
    return false;
  }
  return true;
}

// A rig observation of a refined point has it as its fourth block; when the
// point is later held (UpdateResidualBlocks), the solver treats it as a
// constant, the same residual as one made with the point fixed.
void RigAdjustment::AddResidualBlocks(
    const std::vector<MapObservationRef>& map_observations) {
  // The costs are made on all threads (10^6 allocations), then given to the
  // solver in observation order.
  const int64_t num_rig = static_cast<int64_t>(observations_.size());
  const int64_t num_map = static_cast<int64_t>(map_observations.size());
  map_costs_.resize(num_map);
#pragma omp parallel for schedule(static) num_threads(NumThreads())
  for (int64_t k = 0; k < num_rig + num_map; ++k) {
    if (k < num_rig) {
      Observation& observation = observations_[k];
      const RigImage& image = dataset_.images[observation.image];
      const Correspondence& correspondence = CorrespondenceOf(observation);
      const Eigen::Vector3d* fixed_point =
          observation.refined_slot >= 0 ? nullptr : &correspondence.point3D;
      observation.cost.reset(
          options_.HasTimeModel()
              ? CreateTimedRigReprojectionCost(
                    cameras_[image.camera_index].ModelId(),
                    correspondence.point2D, fixed_point,
                    &frameset_motions_[image.frameset_index])
              : CreateRigReprojectionCost(
                    cameras_[image.camera_index].ModelId(),
                    correspondence.point2D, fixed_point));
    } else {
      const MapObservationRef& observation = map_observations[k - num_rig];
      map_costs_[k - num_rig].reset(CreateRigReprojectionCost(
          map_cameras_[dataset_.map_images[observation.image].camera_index]
              .ModelId(),
          MapObservationOf(observation).point2D, nullptr));
    }
  }
  has_fixed_points_ = false;
  num_rig_residuals_ = observations_.size();
  for (Observation& observation : observations_) {
    const RigImage& image = dataset_.images[observation.image];
    colmap::Camera& camera = cameras_[image.camera_index];
    double* rig_from_world = rig_from_world_[image.frameset_index].data();
    double* cam_from_rig = cam_from_rig_[image.camera_index].data();
    // Blocks: Q, P, theta[, delta, rho, v (time model)][, X].
    std::vector<double*> blocks = {rig_from_world, cam_from_rig,
                                   camera.ParamsData()};
    if (options_.HasTimeModel()) {
      blocks.push_back(&time_offsets_[image.camera_index]);
      blocks.push_back(&line_delays_[image.camera_index]);
      blocks.push_back(frameset_translations_[image.frameset_index].data());
    }
    if (observation.refined_slot >= 0) {
      blocks.push_back(refined_points_[observation.refined_slot].data());
    } else {
      has_fixed_points_ = true;
    }
    observation.residual_index = solver_->AddResidualBlock(
        observation.cost.get(), loss_.get(), blocks);
  }
  map_residuals_.reserve(map_observations.size());
  for (int64_t k = 0; k < num_map; ++k) {
    const MapObservationRef& observation = map_observations[k];
    colmap::Camera& camera =
        map_cameras_[dataset_.map_images[observation.image].camera_index];
    map_residuals_.emplace_back(
        observation,
        solver_->AddResidualBlock(
            map_costs_[k].get(), loss_.get(),
            {map_cam_from_world_[observation.image].data(),
             identity_pose_.data(), camera.ParamsData(),
             RefinedPoint(MapObservationOf(observation).point3D_id)->data()}));
    has_fixed_points_ = has_fixed_points_ || !options_.refine_map;
  }
  if (options_.HasTimeModel() && options_.refine_rig_poses) {
    std::vector<char> frameset_refined(rig_from_world_.size(), 0);
    for (const Observation& observation : observations_) {
      frameset_refined[dataset_.images[observation.image].frameset_index] = 1;
    }
    AddTranslationPriors(frameset_refined);
  }
}

void RigAdjustment::UpdateResidualBlocks() {
  // The rig observations' blocks are the first num_rig_residuals_.
  std::vector<char> active(num_rig_residuals_, 0);
  has_fixed_points_ = false;
  for (const Observation& observation : observations_) {
    active[observation.residual_index] = 1;
    has_fixed_points_ = has_fixed_points_ || observation.refined_slot < 0;
  }
  for (const auto& [observation, index] : map_residuals_) {
    const bool in_problem =
        !map_rejected_[observation.image][observation.observation] &&
        IsPointRefined(MapObservationOf(observation).point3D_id);
    solver_->SetResidualBlockActive(index, in_problem);
    has_fixed_points_ =
        has_fixed_points_ || (in_problem && !options_.refine_map);
  }
  for (size_t index = 0; index < active.size(); ++index) {
    solver_->SetResidualBlockActive(index, active[index] != 0);
  }
}

// Groups (rows of the reduced system): every refined rig pose and map pose
// on its own, every rig camera's cam_from_rig and intrinsics together (an
// observation then couples two groups, not three), every refined map
// camera's intrinsics. Blocks that are not added are held constant. The
// points are added in point3D_id order.
void RigAdjustment::AddParameterBlocks(
    const std::vector<MapObservationRef>& map_observations) {
  // Only the blocks that the observations use.
  std::vector<char> frameset_used(rig_from_world_.size(), 0);
  std::vector<char> camera_used(cameras_.size(), 0);
  for (const Observation& observation : observations_) {
    const RigImage& image = dataset_.images[observation.image];
    frameset_used[image.frameset_index] = 1;
    camera_used[image.camera_index] = 1;
  }
  std::vector<char> map_image_used(map_cam_from_world_.size(), 0);
  std::vector<char> map_camera_used(map_cameras_.size(), 0);
  for (const MapObservationRef& observation : map_observations) {
    map_image_used[observation.image] = 1;
    map_camera_used[dataset_.map_images[observation.image].camera_index] = 1;
  }
  int group = 0;
  if (options_.refine_rig_poses) {
    // With the time model a frameset's velocity and acceleration are in its
    // pose's group.
    for (size_t frameset = 0; frameset < rig_from_world_.size(); ++frameset) {
      if (!frameset_used[frameset]) continue;
      solver_->AddParameterBlock(rig_from_world_[frameset].data(), 7,
                                 pose_manifold_.get(), group);
      if (options_.HasTimeModel()) {
        solver_->AddParameterBlock(frameset_translations_[frameset].data(), 6,
                                   nullptr, group);
      }
      ++group;
    }
  }
  if (options_.refine_map) {
    for (size_t image = 0; image < map_cam_from_world_.size(); ++image) {
      if (!map_image_used[image]) continue;
      solver_->AddParameterBlock(map_cam_from_world_[image].data(), 7,
                                 pose_manifold_.get(), group++);
    }
    for (size_t camera = 0;
         options_.refine_map_intrinsics && camera < map_cameras_.size();
         ++camera) {
      if (!map_camera_used[camera]) continue;
      solver_->AddParameterBlock(
          map_cameras_[camera].ParamsData(),
          static_cast<int>(map_cameras_[camera].NumParams()), nullptr, group++);
    }
  }
  intrinsics_manifolds_.clear();
  for (size_t camera = 0; camera < cameras_.size(); ++camera) {
    if (!camera_used[camera]) continue;
    bool in_group = false;
    if (options_.refine_extrinsics &&
        static_cast<int>(camera) != dataset_.reference_camera) {
      solver_->AddParameterBlock(cam_from_rig_[camera].data(), 7,
                                 pose_manifold_.get(), group);
      in_group = true;
    }
    const IntrinsicsRefinement method_refinement = {
        options_.refine_focal_length, options_.refine_principal_point,
        options_.refine_extra_params};
    const std::vector<int> constant_params = HeldParamIdxs(
        cameras_[camera],
        method_refinement.And(dataset_.cameras[camera].refinement));
    const int num_params = static_cast<int>(cameras_[camera].NumParams());
    if (static_cast<int>(constant_params.size()) < num_params) {
      const ceres::Manifold* manifold = nullptr;
      if (!constant_params.empty()) {
        intrinsics_manifolds_.push_back(std::make_unique<ceres::SubsetManifold>(
            num_params, constant_params));
        manifold = intrinsics_manifolds_.back().get();
      }
      solver_->AddParameterBlock(cameras_[camera].ParamsData(), num_params,
                                 manifold, group);
      in_group = true;
    }
    // The time model's blocks, in the camera's group: an observation still
    // couples two block rows. The reference camera's offset stays 0: it
    // defines the rig's clock.
    if (options_.estimate_time_offsets &&
        static_cast<int>(camera) != dataset_.reference_camera) {
      solver_->AddParameterBlock(&time_offsets_[camera], 1, nullptr, group);
      in_group = true;
    }
    if (options_.estimate_line_delays) {
      solver_->AddParameterBlock(&line_delays_[camera], 1, nullptr, group);
      in_group = true;
    }
    group += in_group ? 1 : 0;
  }
  for (Eigen::Vector3d& point : refined_points_) {
    solver_->AddPoint(point.data());
  }
}

}  // namespace rig_calibrator
