// The Ceres problem of the final bundle adjustment: one RigReprojectionCost
// per observation (a map image's: its cam_from_world as the "rig" pose, a
// constant identity cam_from_rig), the blocks that are held constant or partly
// constant, and the solver set-up (Schur elimination of the rig poses or map
// points).
#include <glog/logging.h>

#include <algorithm>
#include <thread>

#include "src/calibration/rig_adjustment.h"
#include "src/geometry/rig_reprojection_cost.h"

namespace rig_calibrator {

bool RigAdjustment::Solve(double function_tolerance,
                          ceres::Solver::Summary* summary) {
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  if (options_.refine_points) {
    SelectRefinedPoints();
  }
  AddResidualBlocks(&problem);
  SetUpParameterBlocks(&problem);
  const ceres::Solver::Options solver_options =
      SolverOptions(problem, function_tolerance);
  VLOG(1) << "Final bundle adjustment: " << problem.NumResidualBlocks()
          << " observations (" << problem.NumResiduals() << " residuals), "
          << problem.NumParameterBlocks() << " parameter blocks";
  ceres::Solve(solver_options, &problem, summary);
  VLOG(1) << summary->BriefReport();
  VLOG(1) << summary->FullReport();
  if (!summary->IsSolutionUsable()) {
    LOG(ERROR) << "Final bundle adjustment failed: " << summary->message;
    return false;
  }
  return true;
}

void RigAdjustment::AddResidualBlocks(ceres::Problem* problem) {
  has_fixed_points_ = false;
  for (const Observation& observation : observations_) {
    const RigImage& image = dataset_.images[observation.image];
    const Correspondence& correspondence = CorrespondenceOf(observation);
    colmap::Camera& camera = cameras_[image.camera_index];
    double* rig_from_world = rig_from_world_[image.frameset_index].data();
    double* cam_from_rig = cam_from_rig_[image.camera_index].data();
    if (IsPointRefined(correspondence)) {
      problem->AddResidualBlock(
          CreateRigReprojectionCost(camera.ModelId(), correspondence.point2D,
                                    nullptr),
          loss_.get(), rig_from_world, cam_from_rig, camera.ParamsData(),
          RefinedPoint(correspondence.point3D_id)->data());
    } else {
      has_fixed_points_ = true;
      problem->AddResidualBlock(
          CreateRigReprojectionCost(camera.ModelId(), correspondence.point2D,
                                    &correspondence.point3D),
          loss_.get(), rig_from_world, cam_from_rig, camera.ParamsData());
    }
  }
  for (const MapObservationRef& observation : MapObservationsInProblem()) {
    const MapObservation& map_observation = MapObservationOf(observation);
    colmap::Camera& camera =
        map_cameras_[dataset_.map_images[observation.image].camera_index];
    problem->AddResidualBlock(
        CreateRigReprojectionCost(camera.ModelId(), map_observation.point2D,
                                  nullptr),
        loss_.get(), map_cam_from_world_[observation.image].data(),
        identity_pose_.data(), camera.ParamsData(),
        RefinedPoint(map_observation.point3D_id)->data());
    has_fixed_points_ = has_fixed_points_ || !options_.refine_map;
  }
}

void RigAdjustment::SetUpParameterBlocks(ceres::Problem* problem) {
  if (problem->HasParameterBlock(identity_pose_.data())) {
    problem->SetParameterBlockConstant(identity_pose_.data());
  }
  for (PoseParams& pose : map_cam_from_world_) {
    if (problem->HasParameterBlock(pose.data())) {
      if (options_.refine_map) {
        problem->SetManifold(pose.data(), pose_manifold_.get());
      } else {
        problem->SetParameterBlockConstant(pose.data());
      }
    }
  }
  for (colmap::Camera& camera : map_cameras_) {
    if (problem->HasParameterBlock(camera.ParamsData()) &&
        !(options_.refine_map && options_.refine_map_intrinsics)) {
      problem->SetParameterBlockConstant(camera.ParamsData());
    }
  }
  for (PoseParams& pose : rig_from_world_) {
    if (problem->HasParameterBlock(pose.data())) {
      if (options_.refine_rig_poses) {
        problem->SetManifold(pose.data(), pose_manifold_.get());
      } else {
        problem->SetParameterBlockConstant(pose.data());
      }
    }
  }
  for (size_t camera = 0; camera < cameras_.size(); ++camera) {
    double* pose = cam_from_rig_[camera].data();
    if (problem->HasParameterBlock(pose)) {
      if (options_.refine_extrinsics &&
          static_cast<int>(camera) != dataset_.reference_camera) {
        problem->SetManifold(pose, pose_manifold_.get());
      } else {
        problem->SetParameterBlockConstant(pose);
      }
    }
    double* params = cameras_[camera].ParamsData();
    if (!problem->HasParameterBlock(params)) {
      continue;
    }
    const IntrinsicsRefinement method_refinement = {
        options_.refine_focal_length, options_.refine_principal_point,
        options_.refine_extra_params};
    const std::vector<int> constant_params = HeldParamIdxs(
        cameras_[camera],
        method_refinement.And(dataset_.cameras[camera].refinement));
    const int num_params = static_cast<int>(cameras_[camera].NumParams());
    if (static_cast<int>(constant_params.size()) == num_params) {
      problem->SetParameterBlockConstant(params);
    } else if (!constant_params.empty()) {
      intrinsics_manifolds_.push_back(
          std::make_unique<ceres::SubsetManifold>(num_params, constant_params));
      problem->SetManifold(params, intrinsics_manifolds_.back().get());
    }
  }
}

ceres::Solver::Options RigAdjustment::SolverOptions(
    const ceres::Problem& problem, double function_tolerance) {
  ceres::Solver::Options solver_options;
  solver_options.max_num_iterations = options_.max_num_iterations;
  solver_options.num_threads =
      options_.num_threads > 0
          ? options_.num_threads
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  solver_options.minimizer_progress_to_stdout = options_.print_progress;
  solver_options.logging_type =
      options_.print_progress ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  // Exact data converges quadratically; the default parameter tolerance
  // (relative to the whole parameter vector, dominated by the focal lengths)
  // would stop a few digits short.
  solver_options.parameter_tolerance = 1e-12;
  solver_options.function_tolerance = function_tolerance;

  // Schur elimination group: the variable points when refined (each is seen
  // by several framesets, so the rig poses cannot share the group: the group
  // must be an independent set), else the variable rig poses (each seen only
  // through the shared camera blocks, leaving a tiny dense reduced system).
  //
  // Ceres lists the blocks of one ordering group by address (a
  // std::set<double*>), so no group here holds blocks at unrelated addresses
  // (the camera parameters are a heap vector per camera): before, the output
  // folder's name changed the result at 1e-15. The points are one vector in
  // point3D_id order, the rig poses and the map poses one vector each in
  // their order; every camera block is a group of its own, in camera order.
  // Giving Ceres the ordering also spares it the independent-set search over
  // the whole Hessian graph (a hash set per parameter block), a sizeable part
  // of each solve's preprocessing with ~10^5 points.
  std::vector<double*> points;
  for (Eigen::Vector3d& point : refined_points_) {
    if (problem.HasParameterBlock(point.data())) points.push_back(point.data());
  }
  if (!points.empty()) {
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (double* block : points) ordering->AddElementToGroup(block, 0);
    int group = 1;
    const auto add_group = [&](const std::vector<double*>& blocks) {
      bool added = false;
      for (double* block : blocks) {
        if (problem.HasParameterBlock(block)) {
          ordering->AddElementToGroup(block, group);
          added = true;
        }
      }
      group += added ? 1 : 0;
    };
    std::vector<double*> poses;
    for (PoseParams& pose : rig_from_world_) poses.push_back(pose.data());
    add_group(poses);
    poses.clear();
    for (PoseParams& pose : map_cam_from_world_) poses.push_back(pose.data());
    add_group(poses);
    add_group({identity_pose_.data()});
    for (size_t camera = 0; camera < cameras_.size(); ++camera) {
      add_group({cam_from_rig_[camera].data()});
      add_group({cameras_[camera].ParamsData()});
    }
    for (colmap::Camera& camera : map_cameras_) {
      add_group({camera.ParamsData()});
    }
    solver_options.linear_solver_ordering = ordering;
    solver_options.linear_solver_type = ceres::SPARSE_SCHUR;
    return solver_options;
  }
  std::vector<double*> eliminated;
  if (options_.refine_rig_poses) {
    for (PoseParams& pose : rig_from_world_) {
      if (problem.HasParameterBlock(pose.data())) {
        eliminated.push_back(pose.data());
      }
    }
  }
  if (eliminated.empty()) {
    // Only camera blocks vary: a small sparse normal-equation system.
    solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    return solver_options;
  }
  // The rig poses (one vector: address order = frameset order) in group 0,
  // then every camera's blocks in groups of their own, in camera order
  // (Problem::GetParameterBlocks lists by address too).
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (double* block : eliminated) {
    ordering->AddElementToGroup(block, 0);
  }
  int group = 1;
  for (size_t camera = 0; camera < cameras_.size(); ++camera) {
    for (double* block :
         {cam_from_rig_[camera].data(), cameras_[camera].ParamsData()}) {
      if (problem.HasParameterBlock(block)) {
        ordering->AddElementToGroup(block, group++);
      }
    }
  }
  solver_options.linear_solver_ordering = ordering;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  return solver_options;
}

}  // namespace rig_calibrator
