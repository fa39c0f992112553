#include "src/calibration/final_bundle_adjuster.h"

#include <ceres/ceres.h>
#include <colmap/base/camera_models.h>
#include <glog/logging.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

namespace rig_calibrator {
namespace {

// A pose as one Ceres parameter block, [qw, qx, qy, qz, tx, ty, tz], so that
// a rig pose is a single block of the Schur elimination group.
using PoseParams = std::array<double, 7>;

PoseParams ToPoseParams(const Rigid3d& pose) {
  return {pose.rotation.w(),   pose.rotation.x(),    pose.rotation.y(),
          pose.rotation.z(),   pose.translation.x(), pose.translation.y(),
          pose.translation.z()};
}

Rigid3d FromPoseParams(const PoseParams& params) {
  return Rigid3d(Eigen::Quaterniond(params[0], params[1], params[2], params[3]),
                 Eigen::Vector3d(params[4], params[5], params[6]));
}

// d(R(q) p)/dq for a unit quaternion q = (w, v): from
//   R(q) p = p + 2 w (v x p) + 2 v x (v x p),
//   d/dw = 2 v x p,  d/dv = -2 w [p]x + 2 (v p^T + (v.p) I - 2 p v^T).
// Ceres' QuaternionManifold maps it to the 3 tangent directions.
Eigen::Matrix<double, 3, 4> RotatedPointQuaternionJacobian(
    const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d v = q.vec();
  Eigen::Matrix3d cross_p;
  cross_p << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
  Eigen::Matrix<double, 3, 4> jacobian;
  jacobian.col(0) = 2 * v.cross(p);
  jacobian.rightCols<3>() =
      -2 * q.w() * cross_p +
      2 * (v * p.transpose() + v.dot(p) * Eigen::Matrix3d::Identity() -
           2 * p * v.transpose());
  return jacobian;
}

// The pixel of the normalized point (u, v) through the COLMAP model, with its
// derivatives by (u, v) and, when `d_pixel_d_params` is given, by the model
// parameters (row-major 2 x kNumParams): forward-mode differentiation of the
// templated CameraModel::WorldToImage with kNumDerivatives = 2 (u, v) or
// 2 + kNumParams.
template <typename CameraModel, int kNumDerivatives>
void ProjectWithJacobians(const double* params, double u, double v,
                          double* pixel, Eigen::Matrix2d* d_pixel_d_uv,
                          double* d_pixel_d_params) {
  using Jet = ceres::Jet<double, kNumDerivatives>;
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  Jet jet_params[kNumParams];
  for (int k = 0; k < kNumParams; ++k) {
    jet_params[k] =
        kNumDerivatives > 2 ? Jet(params[k], 2 + k) : Jet(params[k]);
  }
  Jet x, y;
  CameraModel::WorldToImage(jet_params, Jet(u, 0), Jet(v, 1), &x, &y);
  pixel[0] = x.a;
  pixel[1] = y.a;
  *d_pixel_d_uv << x.v[0], x.v[1], y.v[0], y.v[1];
  if (d_pixel_d_params != nullptr) {
    for (int k = 0; k < kNumParams; ++k) {
      d_pixel_d_params[k] = x.v[2 + k];
      d_pixel_d_params[kNumParams + k] = y.v[2 + k];
    }
  }
}

// Reprojection error of a map point seen by a rig camera,
//   r = pi_theta(P (Q X)) - x,
// Q = rig_from_world, P = cam_from_rig (blocks [qw, qx, qy, qz, tx, ty, tz]),
// theta the camera model's parameters, X a fixed point or a fourth block.
// The pose Jacobians are analytic and only the camera model is
// differentiated with Jets (2 + kNumParams derivatives instead of the
// 17 + kNumParams of a fully auto-differentiated functor): the Jacobian
// evaluation dominates the final bundle adjustment. A point that is not in
// front of the camera is an invalid evaluation for Ceres (the step is
// rejected) rather than a NaN.
template <typename CameraModel>
class RigReprojectionError final : public ceres::CostFunction {
 public:
  static constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);

  RigReprojectionError(const Eigen::Vector2d& observed,
                       const Eigen::Vector3d* point3D)
      : observed_(observed),
        fixed_point3D_(point3D != nullptr ? *point3D : Eigen::Vector3d::Zero()),
        variable_point_(point3D == nullptr) {
    set_num_residuals(2);
    *mutable_parameter_block_sizes() = {7, 7, kNumParams};
    if (variable_point_) {
      mutable_parameter_block_sizes()->push_back(3);
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* rig_from_world = parameters[0];
    const double* cam_from_rig = parameters[1];
    const double* camera_params = parameters[2];
    const Eigen::Quaterniond rig_rotation(rig_from_world[0], rig_from_world[1],
                                          rig_from_world[2], rig_from_world[3]);
    const Eigen::Quaterniond cam_rotation(cam_from_rig[0], cam_from_rig[1],
                                          cam_from_rig[2], cam_from_rig[3]);
    const Eigen::Matrix3d rig_rotation_matrix = rig_rotation.toRotationMatrix();
    const Eigen::Matrix3d cam_rotation_matrix = cam_rotation.toRotationMatrix();
    const Eigen::Vector3d point3D =
        variable_point_ ? Eigen::Vector3d(parameters[3]) : fixed_point3D_;
    const Eigen::Vector3d point_in_rig =
        rig_rotation_matrix * point3D + Eigen::Vector3d(rig_from_world + 4);
    const Eigen::Vector3d point_in_cam =
        cam_rotation_matrix * point_in_rig + Eigen::Vector3d(cam_from_rig + 4);
    const double z = point_in_cam.z();
    if (!(z > 0)) {
      return false;
    }
    const double u = point_in_cam.x() / z;
    const double v = point_in_cam.y() / z;
    if (jacobians == nullptr) {
      CameraModel::WorldToImage(camera_params, u, v, &residuals[0],
                                &residuals[1]);
      residuals[0] -= observed_.x();
      residuals[1] -= observed_.y();
      return true;
    }

    Eigen::Matrix2d d_pixel_d_uv;
    if (jacobians[2] != nullptr) {
      ProjectWithJacobians<CameraModel, 2 + kNumParams>(
          camera_params, u, v, residuals, &d_pixel_d_uv, jacobians[2]);
    } else {
      ProjectWithJacobians<CameraModel, 2>(camera_params, u, v, residuals,
                                           &d_pixel_d_uv, nullptr);
    }
    residuals[0] -= observed_.x();
    residuals[1] -= observed_.y();

    // d(u, v)/d point_in_cam = [1/z, 0, -u/z; 0, 1/z, -v/z].
    Eigen::Matrix<double, 2, 3> d_pixel_d_cam;
    d_pixel_d_cam.col(0) = d_pixel_d_uv.col(0) / z;
    d_pixel_d_cam.col(1) = d_pixel_d_uv.col(1) / z;
    d_pixel_d_cam.col(2) =
        -(u * d_pixel_d_uv.col(0) + v * d_pixel_d_uv.col(1)) / z;
    using PoseJacobian = Eigen::Matrix<double, 2, 7, Eigen::RowMajor>;
    if (jacobians[1] != nullptr) {
      Eigen::Map<PoseJacobian> jacobian(jacobians[1]);
      jacobian.leftCols<4>() = d_pixel_d_cam * RotatedPointQuaternionJacobian(
                                                   cam_rotation, point_in_rig);
      jacobian.rightCols<3>() = d_pixel_d_cam;
    }
    const Eigen::Matrix<double, 2, 3> d_pixel_d_rig =
        d_pixel_d_cam * cam_rotation_matrix;
    if (jacobians[0] != nullptr) {
      Eigen::Map<PoseJacobian> jacobian(jacobians[0]);
      jacobian.leftCols<4>() =
          d_pixel_d_rig * RotatedPointQuaternionJacobian(rig_rotation, point3D);
      jacobian.rightCols<3>() = d_pixel_d_rig;
    }
    if (variable_point_ && jacobians[3] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jacobian(
          jacobians[3]);
      jacobian = d_pixel_d_rig * rig_rotation_matrix;
    }
    return true;
  }

 private:
  const Eigen::Vector2d observed_;
  const Eigen::Vector3d fixed_point3D_;
  const bool variable_point_;
};

double Median(std::vector<double> values) {
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// One correspondence of one dataset image.
struct Observation {
  int image = -1;
  int correspondence = -1;
};

// Where a point is and its residual at the current estimate.
struct ObservationError {
  double depth = 0;  // z in the camera frame
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();
};

// The state being refined (copies of the calibration, written back on
// success) and the bookkeeping of which observations take part.
class RigAdjustment {
 public:
  RigAdjustment(const FinalBundleAdjustmentOptions& options,
                const RigDataset& dataset, const RigCalibration& calibration)
      : options_(options), dataset_(dataset), cameras_(calibration.cameras) {
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

  size_t NumObservations() const { return observations_.size(); }
  size_t NumRejected() const {
    return num_given_inliers_ - observations_.size();
  }

  ObservationError Evaluate(const Observation& observation) const {
    const RigImage& image = dataset_.images[observation.image];
    const Correspondence& correspondence =
        image.correspondences[observation.correspondence];
    const Rigid3d cam_from_world =
        FromPoseParams(cam_from_rig_[image.camera_index]) *
        FromPoseParams(rig_from_world_[image.frameset_index]);
    const Eigen::Vector3d point_in_cam =
        cam_from_world * PointOf(correspondence);
    ObservationError error;
    error.depth = point_in_cam.z();
    if (error.depth > 0) {
      error.residual = cameras_[image.camera_index].WorldToImage(
                           point_in_cam.hnormalized()) -
                       correspondence.point2D;
    }
    return error;
  }

  // RMS of |r| over the current observations.
  double RmsError() const {
    double sum = 0;
    for (const Observation& observation : observations_) {
      sum += Evaluate(observation).residual.squaredNorm();
    }
    return observations_.empty() ? 0 : std::sqrt(sum / observations_.size());
  }

  // Removes observations behind their camera or farther than
  // max_depth_factor * the median depth; with `prune_residuals` also those
  // whose error exceeds their camera's threshold (see the options). Returns
  // how many were removed.
  size_t RejectOutliers(bool prune_residuals) {
    std::vector<ObservationError> errors(observations_.size());
    std::vector<double> depths;
    depths.reserve(observations_.size());
    for (size_t k = 0; k < observations_.size(); ++k) {
      errors[k] = Evaluate(observations_[k]);
      if (errors[k].depth > 0) {
        depths.push_back(errors[k].depth);
      }
    }
    const double max_depth =
        depths.empty() ? 0 : options_.max_depth_factor * Median(depths);
    std::vector<double> max_error_px(cameras_.size(),
                                     std::numeric_limits<double>::infinity());
    if (prune_residuals) {
      max_error_px = MaxErrorPerCamera(errors);
    }
    std::vector<Observation> kept;
    kept.reserve(observations_.size());
    for (size_t k = 0; k < observations_.size(); ++k) {
      const int camera = dataset_.images[observations_[k].image].camera_index;
      if (errors[k].depth > 0 && errors[k].depth <= max_depth &&
          errors[k].residual.norm() <= max_error_px[camera]) {
        kept.push_back(observations_[k]);
      }
    }
    const size_t num_removed = observations_.size() - kept.size();
    observations_ = std::move(kept);
    return num_removed;
  }

  // Builds the problem over the current observations and solves it.
  bool Solve(ceres::Solver::Summary* summary);

  // Moves the solution by the similarity that maps the refined points back
  // onto their map positions, when no fixed point anchors the world frame.
  void AnchorToMap();

  // Writes the estimate and the per-image results.
  void WriteTo(RigCalibration* calibration) const;

 private:
  const Eigen::Vector3d& PointOf(const Correspondence& correspondence) const {
    if (correspondence.point3D_id >= 0) {
      const auto it = refined_points_.find(correspondence.point3D_id);
      if (it != refined_points_.end()) {
        return it->second;
      }
    }
    return correspondence.point3D;
  }

  bool IsPointRefined(const Correspondence& correspondence) const {
    return correspondence.point3D_id >= 0 &&
           refined_points_.count(correspondence.point3D_id) > 0;
  }

  // The points to refine in the next solve: those with an id that the
  // current observations see at least twice (seen once, a point has 3
  // unknowns for 2 residuals). They keep their refined position from an
  // earlier solve, or start at their map position.
  void SelectRefinedPoints() {
    std::unordered_map<int64_t, int> num_observations;
    for (const Observation& observation : observations_) {
      const Correspondence& correspondence =
          dataset_.images[observation.image]
              .correspondences[observation.correspondence];
      if (correspondence.point3D_id >= 0) {
        ++num_observations[correspondence.point3D_id];
        map_points_.emplace(correspondence.point3D_id, correspondence.point3D);
      }
    }
    std::unordered_map<int64_t, Eigen::Vector3d> refined_points;
    for (const auto& [point3D_id, count] : num_observations) {
      if (count >= 2) {
        const auto it = refined_points_.find(point3D_id);
        refined_points[point3D_id] = it != refined_points_.end()
                                         ? it->second
                                         : map_points_.at(point3D_id);
      }
    }
    refined_points_ = std::move(refined_points);
  }

  std::vector<double> MaxErrorPerCamera(
      const std::vector<ObservationError>& errors) const {
    std::vector<std::vector<double>> components(cameras_.size());
    for (size_t k = 0; k < observations_.size(); ++k) {
      if (errors[k].depth > 0) {
        const int camera = dataset_.images[observations_[k].image].camera_index;
        components[camera].push_back(errors[k].residual.x());
        components[camera].push_back(errors[k].residual.y());
      }
    }
    std::vector<double> max_error_px(cameras_.size(),
                                     options_.min_outlier_error_px);
    for (size_t camera = 0; camera < cameras_.size(); ++camera) {
      if (components[camera].empty()) {
        continue;
      }
      const double median = Median(components[camera]);
      for (double& component : components[camera]) {
        component = std::abs(component - median);
      }
      const double sigma = 1.4826 * Median(components[camera]);
      max_error_px[camera] = std::max(options_.min_outlier_error_px,
                                      options_.outlier_sigma_factor * sigma);
    }
    return max_error_px;
  }

  void SetUpParameterBlocks(ceres::Problem* problem);
  ceres::Solver::Options SolverOptions(const ceres::Problem& problem);

  const FinalBundleAdjustmentOptions& options_;
  const RigDataset& dataset_;
  std::vector<colmap::Camera> cameras_;
  std::vector<PoseParams> cam_from_rig_;
  std::vector<PoseParams> rig_from_world_;
  std::vector<bool> has_rig_pose_;
  std::vector<Observation> observations_;
  size_t num_given_inliers_ = 0;
  // By point3D_id: the map positions and the points being refined.
  std::unordered_map<int64_t, Eigen::Vector3d> map_points_;
  std::unordered_map<int64_t, Eigen::Vector3d> refined_points_;
  bool has_fixed_points_ = false;
  // Ceres does not own these; they outlive every problem built here.
  std::unique_ptr<ceres::LossFunction> loss_ =
      std::make_unique<ceres::CauchyLoss>(options_.loss_scale_px);
  std::unique_ptr<ceres::Manifold> pose_manifold_ =
      std::make_unique<ceres::ProductManifold<ceres::QuaternionManifold,
                                              ceres::EuclideanManifold<3>>>();
  std::vector<std::unique_ptr<ceres::Manifold>> intrinsics_manifolds_;
};

void RigAdjustment::SetUpParameterBlocks(ceres::Problem* problem) {
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
    std::vector<int> constant_params;
    const auto hold = [&](const std::vector<size_t>& idxs) {
      constant_params.insert(constant_params.end(), idxs.begin(), idxs.end());
    };
    if (!options_.refine_focal_length) {
      hold(cameras_[camera].FocalLengthIdxs());
    }
    if (!options_.refine_principal_point) {
      hold(cameras_[camera].PrincipalPointIdxs());
    }
    if (!options_.refine_extra_params) {
      hold(cameras_[camera].ExtraParamsIdxs());
    }
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
    const ceres::Problem& problem) {
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
  // Stop when an iteration lowers the cost by less than 1e-5 of it (Ceres'
  // default 1e-6). With refined map points the last iterations only polish
  // tens of thousands of points: 500 framesets x 10 cameras, final BA 58 s ->
  // 40 s, 200 x 10: 24 -> 12 s, with the same errors against the truth (and
  // the same on the rendered demo); exact data still converge to 1e-8.
  solver_options.function_tolerance = 1e-5;

  // Schur elimination group: the variable points when refined (each is seen
  // by several framesets, so the rig poses cannot share the group: the group
  // must be an independent set), else the variable rig poses (each seen only
  // through the shared camera blocks, leaving a tiny dense reduced system).
  std::vector<double*> eliminated;
  for (auto& [point3D_id, point] : refined_points_) {
    if (problem.HasParameterBlock(point.data())) {
      eliminated.push_back(point.data());
    }
  }
  const bool eliminate_points = !eliminated.empty();
  if (!eliminate_points && options_.refine_rig_poses) {
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
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  std::vector<double*> blocks;
  problem.GetParameterBlocks(&blocks);
  for (double* block : blocks) {
    ordering->AddElementToGroup(block, 1);
  }
  for (double* block : eliminated) {
    ordering->AddElementToGroup(block, 0);
  }
  solver_options.linear_solver_ordering = ordering;
  solver_options.linear_solver_type =
      eliminate_points ? ceres::SPARSE_SCHUR : ceres::DENSE_SCHUR;
  return solver_options;
}

bool RigAdjustment::Solve(ceres::Solver::Summary* summary) {
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  if (options_.refine_points) {
    SelectRefinedPoints();
  }
  has_fixed_points_ = false;
  for (const Observation& observation : observations_) {
    const RigImage& image = dataset_.images[observation.image];
    const Correspondence& correspondence =
        image.correspondences[observation.correspondence];
    colmap::Camera& camera = cameras_[image.camera_index];
    double* rig_from_world = rig_from_world_[image.frameset_index].data();
    double* cam_from_rig = cam_from_rig_[image.camera_index].data();
    if (IsPointRefined(correspondence)) {
      problem.AddResidualBlock(
          CreateRigReprojectionError(camera.ModelId(), correspondence.point2D,
                                     nullptr),
          loss_.get(), rig_from_world, cam_from_rig, camera.ParamsData(),
          refined_points_.at(correspondence.point3D_id).data());
    } else {
      has_fixed_points_ = true;
      problem.AddResidualBlock(
          CreateRigReprojectionError(camera.ModelId(), correspondence.point2D,
                                     &correspondence.point3D),
          loss_.get(), rig_from_world, cam_from_rig, camera.ParamsData());
    }
  }
  SetUpParameterBlocks(&problem);
  const ceres::Solver::Options solver_options = SolverOptions(problem);
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

void RigAdjustment::AnchorToMap() {
  if (has_fixed_points_ || refined_points_.size() < 3) {
    return;
  }
  Eigen::Matrix3Xd refined(3, refined_points_.size());
  Eigen::Matrix3Xd mapped(3, refined_points_.size());
  int column = 0;
  for (const auto& [point3D_id, point] : refined_points_) {
    refined.col(column) = point;
    mapped.col(column) = map_points_.at(point3D_id);
    ++column;
  }
  // X_map = s R X + t. The world frame moves to the map's; the rig and camera
  // frames scale by s with it, so every projection X/Z is unchanged:
  //   Q' = (R_Q R^T, s t_Q - R_Q R^T t),  P' = (R_P, s t_P).
  const Eigen::Matrix4d similarity = Eigen::umeyama(refined, mapped, true);
  const Eigen::Matrix3d scaled_rotation = similarity.topLeftCorner<3, 3>();
  const double scale = std::cbrt(scaled_rotation.determinant());
  const Eigen::Matrix3d rotation = scaled_rotation / scale;
  const Eigen::Vector3d translation = similarity.topRightCorner<3, 1>();
  for (auto& [point3D_id, point] : refined_points_) {
    point = scaled_rotation * point + translation;
  }
  for (size_t frameset = 0; frameset < rig_from_world_.size(); ++frameset) {
    if (!has_rig_pose_[frameset]) {
      continue;
    }
    PoseParams& params = rig_from_world_[frameset];
    const Rigid3d rig_from_world = FromPoseParams(params);
    const Eigen::Matrix3d new_rotation =
        rig_from_world.RotationMatrix() * rotation.transpose();
    params =
        ToPoseParams(Rigid3d(new_rotation, scale * rig_from_world.translation -
                                               new_rotation * translation));
  }
  for (PoseParams& params : cam_from_rig_) {
    for (int k = 4; k < 7; ++k) {
      params[k] *= scale;
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

// Checks that the calibration matches the dataset, so that every index used
// later is valid.
bool CheckInput(const FinalBundleAdjustmentOptions& options,
                const RigDataset& dataset, const RigCalibration& calibration) {
  const size_t num_cameras = dataset.cameras.size();
  if (calibration.cameras.size() != num_cameras ||
      calibration.cam_from_rig.size() != num_cameras ||
      calibration.camera_calibrated.size() != num_cameras ||
      calibration.rig_from_world.size() != dataset.frameset_names.size() ||
      calibration.images.size() != dataset.images.size()) {
    LOG(ERROR) << "Final bundle adjustment: the calibration does not match "
                  "the dataset (numbers of cameras, framesets or images)";
    return false;
  }
  if (dataset.reference_camera < 0 ||
      dataset.reference_camera >= static_cast<int>(num_cameras)) {
    LOG(ERROR) << "Final bundle adjustment: invalid reference camera "
               << dataset.reference_camera;
    return false;
  }
  if (!(options.loss_scale_px > 0) || options.max_num_iterations < 1 ||
      !(options.min_outlier_error_px > 0) ||
      !(options.outlier_sigma_factor > 0) || !(options.max_depth_factor > 1) ||
      options.num_pruning_rounds < 0) {
    LOG(ERROR) << "Final bundle adjustment: invalid options (loss scale, "
                  "iterations, outlier thresholds or pruning rounds)";
    return false;
  }
  for (size_t camera = 0; camera < num_cameras; ++camera) {
    const colmap::Camera& intrinsics = calibration.cameras[camera];
    if (calibration.camera_calibrated[camera] &&
        (!colmap::ExistsCameraModelWithId(intrinsics.ModelId()) ||
         !intrinsics.VerifyParams())) {
      LOG(ERROR) << "Final bundle adjustment: camera " << camera
                 << " has an unknown model or a wrong number of parameters";
      return false;
    }
  }
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    if (image.camera_index < 0 ||
        image.camera_index >= static_cast<int>(num_cameras) ||
        image.frameset_index < 0 ||
        image.frameset_index >=
            static_cast<int>(dataset.frameset_names.size())) {
      LOG(ERROR) << "Final bundle adjustment: image " << image.name
                 << " has an invalid camera or frameset index";
      return false;
    }
    const std::vector<char>& mask = calibration.images[i].inlier_mask;
    if (!mask.empty() && mask.size() != image.correspondences.size()) {
      LOG(ERROR) << "Final bundle adjustment: the inlier mask of image "
                 << image.name << " has " << mask.size() << " entries for "
                 << image.correspondences.size() << " correspondences";
      return false;
    }
    for (const Correspondence& correspondence : image.correspondences) {
      if (!correspondence.point2D.allFinite() ||
          !correspondence.point3D.allFinite()) {
        LOG(ERROR) << "Final bundle adjustment: image " << image.name
                   << " has a non-finite correspondence";
        return false;
      }
    }
  }
  return true;
}

}  // namespace

ceres::CostFunction* CreateRigReprojectionError(
    int model_id, const Eigen::Vector2d& observed,
    const Eigen::Vector3d* point3D) {
  switch (model_id) {
#define CAMERA_MODEL_CASE(CameraModel) \
  case colmap::CameraModel::kModelId:  \
    return new RigReprojectionError<colmap::CameraModel>(observed, point3D);
    CAMERA_MODEL_CASES
#undef CAMERA_MODEL_CASE
    default:
      return nullptr;
  }
}

bool AdjustRig(const FinalBundleAdjustmentOptions& options,
               const RigDataset& dataset, RigCalibration* calibration,
               FinalBundleAdjustmentSummary* summary) {
  const auto start_time = std::chrono::steady_clock::now();
  if (calibration == nullptr || !CheckInput(options, dataset, *calibration)) {
    return false;
  }
  RigAdjustment adjustment(options, dataset, *calibration);
  adjustment.RejectOutliers(/*prune_residuals=*/false);
  if (adjustment.NumObservations() == 0) {
    LOG(ERROR) << "Final bundle adjustment: no inlier correspondence of a "
                  "calibrated camera in a frameset with a rig pose";
    return false;
  }
  FinalBundleAdjustmentSummary result;
  result.initial_rms_px = adjustment.RmsError();
  ceres::Solver::Summary ceres_summary;
  for (int round = 0;; ++round) {
    if (!adjustment.Solve(&ceres_summary)) {
      return false;
    }
    result.num_residuals = static_cast<int>(adjustment.NumObservations());
    result.num_iterations += ceres_summary.num_successful_steps +
                             ceres_summary.num_unsuccessful_steps;
    if (round == options.num_pruning_rounds) {
      break;
    }
    const size_t num_pruned =
        adjustment.RejectOutliers(/*prune_residuals=*/true);
    VLOG(1) << "Final bundle adjustment: pruned " << num_pruned
            << " outlier observations";
    if (num_pruned == 0) {
      break;
    }
    if (adjustment.NumObservations() == 0) {
      LOG(ERROR) << "Final bundle adjustment: every observation was pruned";
      return false;
    }
  }
  if (options.refine_points) {
    adjustment.AnchorToMap();
  }
  adjustment.WriteTo(calibration);
  result.final_rms_px = adjustment.RmsError();
  result.num_outliers = static_cast<int>(adjustment.NumRejected());
  result.ceres_report = ceres_summary.BriefReport();
  result.seconds = std::chrono::duration<double>(
                       std::chrono::steady_clock::now() - start_time)
                       .count();
  VLOG(1) << "Final bundle adjustment: RMS " << result.initial_rms_px << " -> "
          << result.final_rms_px << " px over " << result.num_residuals
          << " observations, " << result.num_outliers << " outliers, "
          << result.seconds << " s";
  if (summary != nullptr) {
    *summary = result;
  }
  return true;
}

}  // namespace rig_calibrator
