#include "src/calibration/calibration_uncertainty.h"

#include <colmap/base/camera_models.h>
#include <colmap/util/math.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <thread>
#include <unordered_map>
#include <utility>

#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/pipeline_report.h"
#include "src/geometry/frameset_motion.h"
#include "src/geometry/pose_jacobians.h"
#include "src/geometry/rig_reprojection_cost.h"
#include "src/geometry/tangent_jacobian_cost.h"
#include "src/geometry/timed_rig_reprojection_cost.h"
#include "src/geometry/translation_prior_cost.h"
#include "src/rig/rig_dataset.h"
#include "src/solvers/bundle_levenberg_marquardt.h"
#include "src/solvers/huge_page_allocator.h"

namespace rig_calibrator {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Fewer clusters (framesets and map images) leave no spread between them
// worth estimating: the between-framesets covariance is not computed.
constexpr int kMinNumClusters = 3;
// Eigenvalues of a Jacobi-scaled (unit-diagonal) information matrix below
// this are directions the data do not determine: with unit diagonal the
// eigenvalues lie in (0, n], and 1e-10 is a condition number of 1e10, far
// beyond any determined calibration (sigma ratio 1e5) and far above the
// rounding of a sum of a million products (1e-16 * 1e6).
constexpr double kMinScaledEigenvalue = 1e-10;
// At most this many map images and framesets whose poses the data do not
// determine are left out before the uncertainty is given up
// (EstimateCalibrationUncertainty).
constexpr int kMaxLeftOutPoses = 20;
// A pixel whose unprojection does not project back within this distance is
// where the estimated model is not invertible: no projection uncertainty.
constexpr double kMaxRoundTripErrorPx = 0.01;

using PoseArray = std::array<double, 7>;  // [qw, qx, qy, qz, tx, ty, tz]

PoseArray ToArray(const Rigid3d& pose) {
  return {pose.rotation.w(),   pose.rotation.x(),    pose.rotation.y(),
          pose.rotation.z(),   pose.translation.x(), pose.translation.y(),
          pose.translation.z()};
}

// The indices of the intrinsic parameters the final adjustment refines
// (rig_adjustment_problem.cc: SetUpParameterBlocks): those the options and
// the camera's own switches (--RigCalibrator.refine_*) both refine.
std::vector<int> FreeIntrinsics(const FinalBundleAdjustmentOptions& options,
                                const IntrinsicsRefinement& refinement,
                                const colmap::Camera& camera) {
  std::vector<char> held(camera.NumParams(), 0);
  const auto hold = [&](const std::vector<size_t>& indices) {
    for (const size_t index : indices) held[index] = 1;
  };
  if (!options.refine_focal_length || !refinement.focal_length) {
    hold(camera.FocalLengthIdxs());
  }
  if (!options.refine_principal_point || !refinement.principal_point) {
    hold(camera.PrincipalPointIdxs());
  }
  if (!options.refine_extra_params || !refinement.extra_params) {
    hold(camera.ExtraParamsIdxs());
  }
  std::vector<int> free;
  for (size_t k = 0; k < held.size(); ++k) {
    if (!held[k]) free.push_back(static_cast<int>(k));
  }
  return free;
}

// One residual block of the final adjustment: the observed pixel of a point
// through a "rig" pose (rig_from_world, or a map image's cam_from_world) and a
// camera pose (cam_from_rig, or the identity for a map image).
struct Observation {
  int model_id = 0;
  // The values (read, never changed: non-const for the solver's
  // interface).
  double* rig_pose = nullptr;
  double* cam_pose = nullptr;
  double* params = nullptr;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector2d observed = Eigen::Vector2d::Zero();
  int point_index = -1;  // into the refined points; -1: fixed point
  int rig_camera = -1;  // the rig camera, -1 for a map image
  // With the time model, a rig observation's capture-time offset and line
  // delay (its camera's).
  double* time_offset = nullptr;
  double* line_delay = nullptr;
  // Its frameset's estimated velocity and acceleration (frameset_motion.h).
  double* translation = nullptr;
  int map_camera = -1;  // a map image's camera
  // The cluster of the between-framesets covariance: the frameset of a rig
  // image, num_framesets + m for map image m.
  int cluster = -1;
  size_t residual = 0;  // its residual block in the solver
};

// A parameter block of the reduced system: O (nuisance: rig poses, map
// poses, map intrinsics) first, then C (rig intrinsics and cam_from_rig).
struct Block {
  int offset = 0;
  int dim = 0;
};

// The pseudo-inverse of a symmetric positive semi-definite matrix through
// its Jacobi-scaled eigen-decomposition, and per row whether it lies in an
// undetermined direction.
Eigen::MatrixXd ScaledPseudoInverse(const Eigen::MatrixXd& matrix,
                                    std::vector<char>* undetermined) {
  const int n = static_cast<int>(matrix.rows());
  undetermined->assign(n, 0);
  Eigen::VectorXd scale(n);
  for (int i = 0; i < n; ++i) {
    scale(i) = matrix(i, i) > 0 ? 1 / std::sqrt(matrix(i, i)) : 0;
    if (!(matrix(i, i) > 0)) (*undetermined)[i] = 1;
  }
  const Eigen::MatrixXd scaled =
      scale.asDiagonal() * matrix * scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  Eigen::MatrixXd inverse = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < n; ++k) {
    const Eigen::VectorXd direction = eigen.eigenvectors().col(k);
    if (eigen.eigenvalues()(k) > kMinScaledEigenvalue) {
      inverse += direction * direction.transpose() / eigen.eigenvalues()(k);
      continue;
    }
    for (int i = 0; i < n; ++i) {
      if (std::abs(direction(i)) > 1e-6) (*undetermined)[i] = 1;
    }
  }
  return scale.asDiagonal() * inverse * scale.asDiagonal();
}

// d(centre)/d(w, t) of a pose x_from_world with centre c = -R^T t, for
// R' = Exp(w) R, t' = t + dt: dc = -R^T [t]x w - R^T dt.
Eigen::Matrix<double, 3, 6> CenterJacobian(const Rigid3d& pose) {
  const Eigen::Matrix3d rotation_t = pose.RotationMatrix().transpose();
  Eigen::Matrix<double, 3, 6> jacobian;
  jacobian.leftCols<3>() =
      -rotation_t * colmap::CrossProductMatrix(pose.translation);
  jacobian.rightCols<3>() = -rotation_t;
  return jacobian;
}

// The reduced system is in the solver's tangent coordinates: a pose's
// (d, t) of RigPoseManifold, R' = Exp(2 d) R. The rotation vector w
// reported is 2 d: per pose coordinate, d(w, t)/d(d, t).
Eigen::Matrix<double, 6, 1> RotationVectorPerTangent() {
  return (Eigen::Matrix<double, 6, 1>() << 2, 2, 2, 1, 1, 1).finished();
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  return values[middle];
}

// The reduced problem of one calibration and its solution.
class UncertaintyProblem {
 public:
  // left_out_map_images, left_out_framesets: per map image and per
  // frameset, left out with its observations (see
  // EstimateCalibrationUncertainty); empty: none.
  UncertaintyProblem(const FinalBundleAdjustmentOptions& ba_options,
                     const RigDataset& dataset,
                     const RigCalibration& calibration,
                     const std::vector<char>& left_out_map_images,
                     const std::vector<char>& left_out_framesets)
      : options_(ba_options),
        dataset_(dataset),
        calibration_(calibration),
        left_out_map_images_(left_out_map_images),
        left_out_framesets_(left_out_framesets) {}

  bool Run(const UncertaintyOptions& options, CalibrationUncertainty* result);
  // After a Run that failed on a singular reduced system: the map image or
  // the frameset whose pose held the smallest pivot, -1 when it was not.
  int undetermined_map_image() const { return undetermined_map_image_; }
  int undetermined_frameset() const { return undetermined_frameset_; }

 private:
  bool SetUpTimeModel(std::string* error);
  void CollectObservations();
  int AddBlock(int dim, std::vector<int>* slot, int index);
  void AssignBlocks();
  bool BuildReducedSystem(std::string* error);
  void AddParameterBlocks();
  void GatherResidualStatistics();
  int NumThreads() const;
  void AddGaugePriors();
  bool Marginalize(CalibrationUncertainty* result);
  std::string DescribeNuisanceParameter(int index) const;
  void AnchorScale();
  void BetweenFramesetsCovariance(const Eigen::MatrixXd& unanchored);
  void FillCameras(const UncertaintyOptions& options,
                   CalibrationUncertainty* result) const;
  void FillProjection(int camera, const UncertaintyOptions& options,
                      CameraUncertainty* uncertainty) const;
  ceres::CostFunction* CostFor(int model_id) const;
  std::string Method() const;

  const FinalBundleAdjustmentOptions& options_;
  const RigDataset& dataset_;
  const RigCalibration& calibration_;

  std::vector<PoseArray> rig_from_world_, cam_from_rig_, map_cam_from_world_;
  std::vector<char> left_out_map_images_, left_out_framesets_;
  int undetermined_map_image_ = -1, undetermined_frameset_ = -1;
  PoseArray identity_ = {1, 0, 0, 0, 0, 0, 0};
  std::vector<std::vector<int>> free_intrinsics_;  // per rig camera
  std::vector<std::vector<int>> map_free_intrinsics_;
  // The intrinsics of the rig cameras and of the map cameras, copied: the
  // solver takes non-const values.
  std::vector<std::vector<double>> params_, map_params_;
  // The time model (final_bundle_adjuster.h), empty without: per rig camera
  // its offset and line delay (the options' values: the result's), per
  // frameset the rig's motion around it from the result's rig poses, held
  // as in the adjustment, and its velocity's and acceleration's weights on
  // the poses (the prior's polynomial, a function of the poses here too).
  std::vector<double> time_offsets_, line_delays_;
  std::vector<FramesetMotion> frameset_motions_;
  std::vector<TranslationStencil> translation_stencils_;
  // Per frameset the estimated velocity and acceleration (the result's,
  // else the motion's p1 and p2), a parameter in its rig pose's block, with
  // its prior as in the adjustment: the autoregression, the costs, and per
  // prior residual its frameset.
  std::vector<TranslationDerivatives> translations_;
  TranslationPrior translation_prior_;
  std::vector<std::unique_ptr<ceres::CostFunction>> translation_prior_costs_;
  std::vector<std::pair<int, size_t>> translation_priors_;
  LargeVector<Observation> observations_;  // 10^6: huge_page_allocator.h
  std::vector<int64_t> point_ids_;  // refined points in the problem
  std::unordered_map<int64_t, int> point_index_;
  std::vector<Eigen::Vector3d> points_;  // positions of the refined points
  int num_rig_observations_ = 0, num_map_observations_ = 0;
  bool has_fixed_points_ = false;
  bool free_gauge_ = false;

  // Reduced blocks and, per parameter owner, its block (-1: none); S's
  // layout (AddParameterBlocks).
  std::vector<Block> blocks_;
  std::vector<int> rig_pose_block_, map_pose_block_, map_intrinsics_block_,
      intrinsics_block_, extrinsics_block_, time_offset_block_,
      line_delay_block_;
  int num_o_ = 0, num_c_ = 0;  // scalar dimensions of O and C
  int num_o_blocks_ = 0;       // blocks [0, num_o_blocks_) are O
  // The final adjustment's problem over observations_ and its reduced
  // system (BuildReducedSystem): the points eliminated, S over O and C.
  RigPoseManifold pose_manifold_;
  std::vector<std::unique_ptr<ceres::SubsetManifold>> intrinsics_manifolds_;
  LargeVector<std::unique_ptr<ceres::CostFunction>> residual_costs_;
  std::unique_ptr<BundleLevenbergMarquardt> solver_;
  // S (both triangles), with the gauge priors once AddGaugePriors added
  // them.
  Eigen::SparseMatrix<double> information_;

  double sum_squared_ = 0, sum_meat_ = 0, sum_bread_ = 0;
  int64_t num_residuals_ = 0, num_parameters_ = 0;
  std::vector<std::vector<double>> distances_;  // per rig camera

  Eigen::VectorXd scale_direction_c_;  // n_C (see the header)
  Eigen::MatrixXd covariance_c_;       // over C, unit noise, gauge as anchored
  std::vector<char> undetermined_c_;
  // Kept for AnchorScale: the factorization of O, R_OC, R_OO^-1 R_OC.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_o_;
  Eigen::VectorXd scale_o_;
  Eigen::MatrixXd r_oc_, x_oc_;
  // With a free gauge, H^-1 a of the anchoring's scale (AnchorScale): over
  // O and C, and per refined point; empty otherwise.
  Eigen::VectorXd anchor_v_;
  std::vector<Eigen::Vector3d> anchor_v_points_;
  // Over C, the between-framesets covariance (BetweenFramesetsCovariance),
  // anchored like covariance_c_ but not scaled by a noise level; and the
  // number of clusters it was computed from (0: not computed).
  Eigen::MatrixXd cluster_covariance_c_;
  int num_clusters_ = 0;
  mutable std::map<int, std::unique_ptr<ceres::CostFunction>> costs_;
};

ceres::CostFunction* UncertaintyProblem::CostFor(int model_id) const {
  auto it = costs_.find(model_id);
  if (it == costs_.end()) {
    it = costs_
             .emplace(
                 model_id,
                 std::unique_ptr<ceres::CostFunction>(CreateRigReprojectionCost(
                     model_id, Eigen::Vector2d::Zero(), nullptr)))
             .first;
  }
  return it->second.get();
}

// With the options' time model: the offsets and line delays of the result
// (the options' values) and the frameset motions of its rig poses.
bool UncertaintyProblem::SetUpTimeModel(std::string* error) {
  if (!options_.HasTimeModel()) return true;
  const size_t num_cameras = calibration_.cameras.size();
  const auto values = [&](const std::vector<double>& given) {
    return given.size() == num_cameras ? given
                                       : std::vector<double>(num_cameras, 0.0);
  };
  time_offsets_ = values(options_.initial_time_offsets_s);
  line_delays_ = values(options_.initial_line_delays_s);
  if (!ComputeFramesetMotions(dataset_.frameset_times_s,
                              calibration_.rig_from_world, &frameset_motions_,
                              error,
                              calibration_.frameset_motions_without_own_pose,
                              &translation_stencils_)) {
    *error = "the time model's frameset motions: " + *error;
    return false;
  }
  translations_ = calibration_.rig_translation_derivatives;
  if (translations_.size() != frameset_motions_.size()) {
    translations_.clear();
    for (const FramesetMotion& motion : frameset_motions_) {
      translations_.push_back(
          Eigen::Map<const TranslationDerivatives>(&motion[9]));
    }
  }
  // The prior the adjustment's next solve would take.
  translation_prior_ = EstimateTranslationPrior(
      frameset_motions_, translations_, calibration_.rig_from_world);
  return true;
}

// The observations of the final adjustment's last state (final_bundle_
// adjuster.h): the inliers of the images of calibrated cameras with a rig
// pose and, with map observations, the map images' non-rejected
// observations of refined points.
void UncertaintyProblem::CollectObservations() {
  for (const Rigid3d& pose : calibration_.cam_from_rig) {
    cam_from_rig_.push_back(ToArray(pose));
  }
  for (const std::optional<Rigid3d>& pose : calibration_.rig_from_world) {
    rig_from_world_.push_back(pose ? ToArray(*pose) : PoseArray{});
  }
  for (size_t c = 0; c < calibration_.cameras.size(); ++c) {
    free_intrinsics_.push_back(FreeIntrinsics(
        options_, dataset_.cameras[c].refinement, calibration_.cameras[c]));
    params_.push_back(calibration_.cameras[c].Params());
  }
  const auto point_index = [&](int64_t point3D_id) {
    const auto [it, inserted] = point_index_.try_emplace(
        point3D_id, static_cast<int>(point_ids_.size()));
    if (inserted) point_ids_.push_back(point3D_id);
    return it->second;
  };
  const bool refine_points = options_.refine_points;
  for (size_t i = 0; i < dataset_.images.size(); ++i) {
    const RigImage& image = dataset_.images[i];
    const int c = image.camera_index;
    if (!calibration_.camera_calibrated[c] ||
        !calibration_.rig_from_world[image.frameset_index] ||
        (static_cast<size_t>(image.frameset_index) <
             left_out_framesets_.size() &&
         left_out_framesets_[image.frameset_index])) {
      continue;
    }
    const std::vector<char>& mask = calibration_.images[i].inlier_mask;
    for (size_t k = 0; k < mask.size(); ++k) {
      if (!mask[k]) continue;
      const Correspondence& correspondence = image.correspondences[k];
      Observation observation;
      observation.model_id = calibration_.cameras[c].ModelId();
      observation.rig_pose = rig_from_world_[image.frameset_index].data();
      observation.cam_pose = cam_from_rig_[c].data();
      observation.params = params_[c].data();
      observation.observed = correspondence.point2D;
      observation.rig_camera = c;
      if (!frameset_motions_.empty()) {
        observation.time_offset = &time_offsets_[c];
        observation.line_delay = &line_delays_[c];
        observation.translation = translations_[image.frameset_index].data();
      }
      const auto refined =
          calibration_.refined_points3D.find(correspondence.point3D_id);
      if (refine_points && correspondence.point3D_id >= 0 &&
          refined != calibration_.refined_points3D.end()) {
        observation.point = refined->second;
        observation.point_index = point_index(correspondence.point3D_id);
      } else if (refine_points && options_.refine_map) {
        // With the map adjusted, a point the adjustment does not refine is
        // one that only this observation sees (final_bundle_adjuster.h):
        // held there, but it says nothing of the calibration, and taken as
        // fixed here it would pin the free world to one or two points
        // (a nearly singular system whose numbers depend on the rounding).
        continue;
      } else {
        observation.point = correspondence.point3D;
        has_fixed_points_ = true;
      }
      observation.cluster = image.frameset_index;
      observations_.push_back(observation);
      ++num_rig_observations_;
    }
  }
  const bool map_results =
      calibration_.map_cam_from_world.size() == dataset_.map_images.size() &&
      calibration_.map_observation_rejected.size() ==
          dataset_.map_images.size() &&
      calibration_.map_cameras.size() == dataset_.map_cameras.size();
  if (refine_points && options_.use_map_observations && map_results) {
    for (const Rigid3d& pose : calibration_.map_cam_from_world) {
      map_cam_from_world_.push_back(ToArray(pose));
    }
    for (const colmap::Camera& camera : calibration_.map_cameras) {
      std::vector<int> all(camera.NumParams());
      for (size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
      map_free_intrinsics_.push_back(all);
      map_params_.push_back(camera.Params());
    }
    for (size_t m = 0; m < dataset_.map_images.size(); ++m) {
      if (m < left_out_map_images_.size() && left_out_map_images_[m]) continue;
      const MapImage& image = dataset_.map_images[m];
      for (size_t k = 0; k < image.observations.size(); ++k) {
        const MapObservation& map_observation = image.observations[k];
        const auto refined =
            calibration_.refined_points3D.find(map_observation.point3D_id);
        if (calibration_.map_observation_rejected[m][k] ||
            refined == calibration_.refined_points3D.end()) {
          continue;
        }
        const colmap::Camera& camera =
            calibration_.map_cameras[image.camera_index];
        Observation observation;
        observation.model_id = camera.ModelId();
        observation.rig_pose = map_cam_from_world_[m].data();
        observation.cam_pose = identity_.data();
        observation.params = map_params_[image.camera_index].data();
        observation.observed = map_observation.point2D;
        observation.point = refined->second;
        observation.point_index = point_index(map_observation.point3D_id);
        observation.cluster =
            static_cast<int>(rig_from_world_.size() + m);
        observation.map_camera = image.camera_index;
        observations_.push_back(observation);
        ++num_map_observations_;
        has_fixed_points_ = has_fixed_points_ || !options_.refine_map;
      }
    }
  }
  free_gauge_ =
      refine_points && options_.refine_rig_poses && !has_fixed_points_;
  for (const int64_t point3D_id : point_ids_) {
    points_.push_back(calibration_.refined_points3D.at(point3D_id));
  }
}

int UncertaintyProblem::AddBlock(int dim, std::vector<int>* slot, int index) {
  if ((*slot)[index] < 0 && dim > 0) {
    (*slot)[index] = static_cast<int>(blocks_.size());
    blocks_.push_back({0, dim});
  }
  return (*slot)[index];
}

// Gives every varying parameter owner with an observation a block: O first
// (rig poses, map poses and map intrinsics, in the observations' order),
// then C (per rig camera its intrinsics, then its cam_from_rig).
void UncertaintyProblem::AssignBlocks() {
  const int num_cameras = static_cast<int>(calibration_.cameras.size());
  rig_pose_block_.assign(rig_from_world_.size(), -1);
  map_pose_block_.assign(map_cam_from_world_.size(), -1);
  map_intrinsics_block_.assign(map_free_intrinsics_.size(), -1);
  intrinsics_block_.assign(num_cameras, -1);
  extrinsics_block_.assign(num_cameras, -1);
  time_offset_block_.assign(num_cameras, -1);
  line_delay_block_.assign(num_cameras, -1);
  std::vector<char> camera_observed(num_cameras, 0);
  const int num_framesets = static_cast<int>(rig_from_world_.size());
  for (const Observation& observation : observations_) {
    if (observation.rig_camera >= 0) {
      if (options_.refine_rig_poses) {
        // With the time model the frameset's velocity and acceleration (6)
        // follow its pose.
        AddBlock(frameset_motions_.empty() ? 6 : 12, &rig_pose_block_,
                 observation.cluster);
      }
      camera_observed[observation.rig_camera] = 1;
    } else if (options_.refine_map) {
      AddBlock(6, &map_pose_block_, observation.cluster - num_framesets);
      if (options_.refine_map_intrinsics) {
        const int camera = observation.map_camera;
        AddBlock(static_cast<int>(map_free_intrinsics_[camera].size()),
                 &map_intrinsics_block_, camera);
      }
    }
  }
  const size_t num_o_blocks = blocks_.size();
  for (int c = 0; c < num_cameras; ++c) {
    if (!camera_observed[c]) continue;
    AddBlock(static_cast<int>(free_intrinsics_[c].size()), &intrinsics_block_,
             c);
    if (options_.refine_extrinsics && c != dataset_.reference_camera) {
      AddBlock(6, &extrinsics_block_, c);
    }
    if (options_.estimate_time_offsets && c != dataset_.reference_camera) {
      AddBlock(1, &time_offset_block_, c);
    }
    if (options_.estimate_line_delays) AddBlock(1, &line_delay_block_, c);
  }
  num_o_blocks_ = static_cast<int>(num_o_blocks);
  int offset = 0;
  for (size_t b = 0; b < blocks_.size(); ++b) {
    if (b == num_o_blocks) num_o_ = offset;
    blocks_[b].offset = offset;
    offset += blocks_[b].dim;
  }
  if (num_o_blocks == blocks_.size()) num_o_ = offset;
  num_c_ = offset - num_o_;
  distances_.assign(num_cameras, {});
}

// p = R_P (R_Q X + t_Q) + t_P for pose arrays Q and P.
Eigen::Vector3d Transform(const double* rig_pose, const double* cam_pose,
                          const Eigen::Vector3d& point) {
  const auto apply = [](const double* pose,
                        const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return Eigen::Quaterniond(pose[0], pose[1], pose[2], pose[3]) * x +
           Eigen::Vector3d(pose[4], pose[5], pose[6]);
  };
  return apply(cam_pose, apply(rig_pose, point));
}

int UncertaintyProblem::NumThreads() const {
  return options_.num_threads > 0
             ? options_.num_threads
             : std::max(1,
                        static_cast<int>(std::thread::hardware_concurrency()));
}

// The parameter blocks of the final adjustment that blocks_ vary, with
// its tangent spaces (poses on RigPoseManifold, partly held intrinsics on a
// SubsetManifold of the held ones), and the refined points in points_'
// order. Groups (the solver's block rows): every O block on its own (group
// b for block b), and, as in the adjustment, every rig camera's intrinsics
// and cam_from_rig together (so an observation couples two groups, not
// three), in that order: AssignBlocks made them consecutive blocks, so the
// groups' columns lie where blocks_ says.
void UncertaintyProblem::AddParameterBlocks() {
  const auto add_intrinsics = [&](std::vector<double>* params,
                                  const std::vector<int>& free, int group) {
    const int num_params = static_cast<int>(params->size());
    const ceres::Manifold* manifold = nullptr;
    if (static_cast<int>(free.size()) < num_params) {
      std::vector<int> held;
      for (int i = 0; i < num_params; ++i) {
        if (!std::binary_search(free.begin(), free.end(), i)) {
          held.push_back(i);
        }
      }
      intrinsics_manifolds_.push_back(
          std::make_unique<ceres::SubsetManifold>(num_params, held));
      manifold = intrinsics_manifolds_.back().get();
    }
    solver_->AddParameterBlock(params->data(), num_params, manifold, group);
  };
  for (size_t f = 0; f < rig_pose_block_.size(); ++f) {
    if (rig_pose_block_[f] < 0) continue;
    solver_->AddParameterBlock(rig_from_world_[f].data(), 7, &pose_manifold_,
                               rig_pose_block_[f]);
    if (!frameset_motions_.empty()) {
      solver_->AddParameterBlock(translations_[f].data(), 6, nullptr,
                                 rig_pose_block_[f]);
    }
  }
  for (size_t m = 0; m < map_pose_block_.size(); ++m) {
    if (map_pose_block_[m] < 0) continue;
    solver_->AddParameterBlock(map_cam_from_world_[m].data(), 7,
                               &pose_manifold_, map_pose_block_[m]);
  }
  for (size_t k = 0; k < map_intrinsics_block_.size(); ++k) {
    if (map_intrinsics_block_[k] < 0) continue;
    add_intrinsics(&map_params_[k], map_free_intrinsics_[k],
                   map_intrinsics_block_[k]);
  }
  int group = num_o_blocks_;
  for (size_t c = 0; c < params_.size(); ++c) {
    if (intrinsics_block_[c] < 0 && extrinsics_block_[c] < 0 &&
        time_offset_block_[c] < 0 && line_delay_block_[c] < 0) {
      continue;
    }
    if (intrinsics_block_[c] >= 0) {
      add_intrinsics(&params_[c], free_intrinsics_[c], group);
    }
    if (extrinsics_block_[c] >= 0) {
      solver_->AddParameterBlock(cam_from_rig_[c].data(), 7, &pose_manifold_,
                                 group);
    }
    if (time_offset_block_[c] >= 0) {
      solver_->AddParameterBlock(&time_offsets_[c], 1, nullptr, group);
    }
    if (line_delay_block_[c] >= 0) {
      solver_->AddParameterBlock(&line_delays_[c], 1, nullptr, group);
    }
    ++group;
  }
  for (Eigen::Vector3d& point : points_) solver_->AddPoint(point.data());
}

// The final adjustment's problem over the observations, registered with the
// own solver (bundle_levenberg_marquardt.h) whatever backend ran the
// adjustment (Ceres' gives no reduced system), and its Gauss-Newton reduced
// system at the result: S = J^T J with the points eliminated
// (LinearizeGaussNewton), in information_.
bool UncertaintyProblem::BuildReducedSystem(std::string* error) {
  BundleSolverOptions solver_options;
  solver_options.num_threads = options_.num_threads;
  solver_ = std::make_unique<BundleLevenbergMarquardt>(solver_options);
  AddParameterBlocks();
  solver_->Reserve(observations_.size(), points_.size());
  // The costs are made on all threads (10^6 allocations), then given to the
  // solver in observation order.
  const int64_t num_observations = static_cast<int64_t>(observations_.size());
  residual_costs_.resize(num_observations);
#pragma omp parallel for schedule(static) num_threads(NumThreads())
  for (int64_t k = 0; k < num_observations; ++k) {
    const Observation& observation = observations_[k];
    const Eigen::Vector3d* fixed_point =
        observation.point_index >= 0 ? nullptr : &observation.point;
    residual_costs_[k].reset(
        observation.time_offset != nullptr
            ? CreateTimedRigReprojectionCost(
                  observation.model_id, observation.observed, fixed_point,
                  &frameset_motions_[observation.cluster])
            : CreateRigReprojectionCost(observation.model_id,
                                        observation.observed, fixed_point));
  }
  std::vector<double*> parameters;
  for (int64_t k = 0; k < num_observations; ++k) {
    Observation& observation = observations_[k];
    const bool refined = observation.point_index >= 0;
    if (residual_costs_[k] == nullptr) {
      *error = "a camera model without a cost function";
      return false;
    }
    parameters.assign(
        {observation.rig_pose, observation.cam_pose, observation.params});
    if (observation.time_offset != nullptr) {
      parameters.push_back(observation.time_offset);
      parameters.push_back(observation.line_delay);
      parameters.push_back(observation.translation);
    }
    if (refined) parameters.push_back(points_[observation.point_index].data());
    observation.residual = solver_->AddResidualBlock(
        residual_costs_[k].get(), nullptr, parameters);
  }
  std::vector<double*> rig_poses(rig_from_world_.size(), nullptr);
  for (size_t f = 0; f < rig_poses.size(); ++f) {
    if (calibration_.rig_from_world[f]) {
      rig_poses[f] = rig_from_world_[f].data();
    }
  }
  for (size_t f = 0; f < rig_pose_block_.size() && !frameset_motions_.empty();
       ++f) {
    if (rig_pose_block_[f] < 0) continue;
    // As the adjustment's (RigAdjustment::AddTranslationPriors).
    for (TranslationPriorTerm& term : MakeTranslationPriorTerms(
             translation_stencils_, rig_poses, &translations_, f,
             f > 0 && rig_pose_block_[f - 1] >= 0, &translation_prior_)) {
      translation_prior_costs_.push_back(std::move(term.cost));
      translation_priors_.emplace_back(
          static_cast<int>(f),
          solver_->AddResidualBlock(translation_prior_costs_.back().get(),
                                    nullptr, term.parameters));
    }
  }
  if (!solver_->LinearizeGaussNewton(error)) return false;
  information_ = solver_->ReducedMatrix().selfadjointView<Eigen::Upper>();
  num_parameters_ += solver_->NumDeterminedPointParameters();
  return true;
}

// The residual statistics of the header (sum |r|^2, and the sums of
// rho'(s)^2 s / 2 and rho'(s) + s rho''(s) of the Cauchy loss) and, per rig
// camera, the distances of its observed points.
void UncertaintyProblem::GatherResidualStatistics() {
  const double loss_b = options_.loss_scale_px * options_.loss_scale_px;
  for (const Observation& observation : observations_) {
    const double s = solver_->Residual(observation.residual).squaredNorm();
    const double u = s / loss_b;
    sum_squared_ += s;
    sum_meat_ += s / 2 / ((1 + u) * (1 + u));  // rho'^2 s / 2
    sum_bread_ += 1 / ((1 + u) * (1 + u));     // rho' + s rho''
    if (observation.rig_camera >= 0) {
      distances_[observation.rig_camera].push_back(
          Transform(observation.rig_pose, observation.cam_pose,
                    observation.point)
              .norm());
    }
  }
  num_residuals_ = 2 * static_cast<int64_t>(observations_.size());
}

// With a free gauge, priors that fix it (any do, see the header): the first
// rig pose (rotation and translation of the world) and the scale, along n_C
// when the rig has a baseline, else along the scale direction of the rig
// pose farthest from the first.
void UncertaintyProblem::AddGaugePriors() {
  scale_direction_c_ = Eigen::VectorXd::Zero(num_c_);
  for (size_t c = 0; c < extrinsics_block_.size(); ++c) {
    if (extrinsics_block_[c] < 0) continue;
    scale_direction_c_.segment<3>(blocks_[extrinsics_block_[c]].offset -
                                  num_o_ + 3) =
        calibration_.cam_from_rig[c].translation;
  }
  if (!free_gauge_) return;
  int first = -1, farthest = -1;
  double max_distance = 0;
  for (size_t f = 0; f < rig_pose_block_.size(); ++f) {
    if (rig_pose_block_[f] < 0) continue;
    if (first < 0) {
      first = static_cast<int>(f);
      continue;
    }
    const double distance = (calibration_.rig_from_world[f]->Center() -
                             calibration_.rig_from_world[first]->Center())
                                .norm();
    if (distance > max_distance) {
      max_distance = distance;
      farthest = static_cast<int>(f);
    }
  }
  if (first < 0) return;
  // The priors as triplets: `prior` on the rows and columns [offset,
  // offset + its size).
  std::vector<Eigen::Triplet<double>> triplets;
  const auto add = [&](int offset, const Eigen::MatrixXd& prior) {
    for (int i = 0; i < prior.rows(); ++i) {
      for (int j = 0; j < prior.cols(); ++j) {
        triplets.emplace_back(offset + i, offset + j, prior(i, j));
      }
    }
  };
  // The weight: the mean information of the first rig pose's (w, t); its
  // prior lambda I over (w, t) is lambda T^2 over the solver's (d, t), T =
  // RotationVectorPerTangent().
  const int first_offset = blocks_[rig_pose_block_[first]].offset;
  const Eigen::Matrix<double, 6, 1> t_squared =
      RotationVectorPerTangent().array().square();
  const double trace =
      (information_.diagonal().segment<6>(first_offset).array() /
       t_squared.array())
          .sum();
  const double weight = trace > 0 ? trace / 6 : 1;
  add(first_offset, weight * Eigen::MatrixXd(t_squared.asDiagonal()));
  if (scale_direction_c_.norm() > 0) {
    // lambda n n^T / |n|^2 over C (n_C is zero outside the cam_from_rig
    // translations).
    add(num_o_, weight * scale_direction_c_ * scale_direction_c_.transpose() /
                    scale_direction_c_.squaredNorm());
  } else if (farthest >= 0) {
    // Scaling about the first rig centre c*: t_Q of rig pose Q moves by
    // -R_Q (c_Q - c*).
    const Rigid3d& pose = *calibration_.rig_from_world[farthest];
    Eigen::VectorXd direction = Eigen::VectorXd::Zero(6);
    direction.tail<3>() =
        -(pose.RotationMatrix() *
          (pose.Center() - calibration_.rig_from_world[first]->Center()))
             .normalized();
    add(blocks_[rig_pose_block_[farthest]].offset,
        weight * direction * direction.transpose());
  }
  Eigen::SparseMatrix<double> priors(information_.rows(), information_.cols());
  priors.setFromTriplets(triplets.begin(), triplets.end());
  information_ += priors;
}

// Covariance over C of the reduced system: S_C = R_CC - R_CO R_OO^-1 R_OC,
// R_OO by a sparse LDL^T factorization of its Jacobi-scaled form.
bool UncertaintyProblem::Marginalize(CalibrationUncertainty* result) {
  const Eigen::VectorXd diagonal_o = information_.diagonal().head(num_o_);
  r_oc_ = information_.topRightCorner(num_o_, num_c_).toDense();
  Eigen::MatrixXd schur =
      information_.bottomRightCorner(num_c_, num_c_).toDense();
  if (num_o_ > 0) {
    Eigen::Index least = 0;
    if (!(diagonal_o.minCoeff(&least) > 0)) {
      result->message = DescribeNuisanceParameter(static_cast<int>(least)) +
                        " has no usable information (no observation "
                        "constrains it, or its information is not a "
                        "positive number): the uncertainty is undetermined";
      return false;
    }
    scale_o_ = diagonal_o.cwiseSqrt().cwiseInverse();
    const Eigen::SparseMatrix<double> r_oo =
        scale_o_.asDiagonal() * information_.topLeftCorner(num_o_, num_o_) *
        scale_o_.asDiagonal();
    ldlt_o_.compute(r_oo);
    if (ldlt_o_.info() != Eigen::Success ||
        !(ldlt_o_.vectorD().minCoeff() > kMinScaledEigenvalue)) {
      result->message =
          "the rig and map poses are not all determined by the data (the "
          "reduced system is singular): the uncertainty is undetermined";
      if (ldlt_o_.info() == Eigen::Success) {
        // The factorization's smallest pivot, in the original order (P A
        // P^T = L D L^T: original index i sits at P.indices()(i)).
        Eigen::Index pivot = 0;
        ldlt_o_.vectorD().minCoeff(&pivot);
        const auto& indices = ldlt_o_.permutationP().indices();
        for (Eigen::Index i = 0; i < indices.size(); ++i) {
          if (indices(i) != pivot) continue;
          result->message += " (first undetermined: " +
                             DescribeNuisanceParameter(static_cast<int>(i)) +
                             ")";
          const auto owner = [&](const std::vector<int>& slot) {
            for (size_t k = 0; k < slot.size(); ++k) {
              const int block = slot[k];
              if (block >= 0 && i >= blocks_[block].offset &&
                  i < blocks_[block].offset + blocks_[block].dim) {
                return static_cast<int>(k);
              }
            }
            return -1;
          };
          undetermined_map_image_ = owner(map_pose_block_);
          undetermined_frameset_ = owner(rig_pose_block_);
          break;
        }
      }
      return false;
    }
    // x_oc = R_OO^-1 R_OC, its columns on all threads: Eigen's solve of
    // several right-hand sides goes column by column, so each is computed
    // as in one solve of all.
    const Eigen::MatrixXd scaled_r_oc = scale_o_.asDiagonal() * r_oc_;
    x_oc_.resize(num_o_, num_c_);
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
    for (int c = 0; c < num_c_; ++c) {
      x_oc_.col(c) = ldlt_o_.solve(scaled_r_oc.col(c));
    }
    x_oc_ = scale_o_.asDiagonal() * x_oc_;
    schur -= r_oc_.transpose() * x_oc_;
  }
  covariance_c_ = ScaledPseudoInverse(schur, &undetermined_c_);
  return true;
}

// What the index-th nuisance (O) parameter belongs to, for messages.
std::string UncertaintyProblem::DescribeNuisanceParameter(int index) const {
  const auto owner_of = [&](const std::vector<int>& slot) {
    for (size_t k = 0; k < slot.size(); ++k) {
      if (slot[k] < 0) continue;
      const Block& block = blocks_[slot[k]];
      if (index >= block.offset && index < block.offset + block.dim) {
        return static_cast<int>(k);
      }
    }
    return -1;
  };
  int owner = owner_of(rig_pose_block_);
  if (owner >= 0) {
    return "the rig pose of frameset " +
           (static_cast<size_t>(owner) < dataset_.frameset_names.size()
                ? dataset_.frameset_names[owner]
                : std::to_string(owner));
  }
  owner = owner_of(map_pose_block_);
  if (owner >= 0) {
    return "the pose of map image " + dataset_.map_images[owner].name;
  }
  owner = owner_of(map_intrinsics_block_);
  if (owner >= 0) return "the intrinsics of map camera " + std::to_string(owner);
  return "parameter " + std::to_string(index);
}

// Cov(d_C - n_C g) for the anchoring's scale g = a^T d (see the header):
// v = H^-1 a by the same elimination (points, then O, then C), then
// Cov - n v_C^T - v_C n^T + (a^T v) n n^T.
void UncertaintyProblem::AnchorScale() {
  Eigen::VectorXd a_o = Eigen::VectorXd::Zero(num_o_);
  std::vector<Eigen::Vector3d> a_points(points_.size(),
                                        Eigen::Vector3d::Zero());
  const bool map_anchor = options_.refine_map;
  if (map_anchor) {
    const std::vector<Rigid3d>& poses = calibration_.map_cam_from_world;
    if (poses.size() < 3) return;  // AnchorMapImagesToMap does not move it
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Rigid3d& pose : poses) mean += pose.Center();
    mean /= poses.size();
    double spread = 0;
    for (const Rigid3d& pose : poses) {
      spread += (pose.Center() - mean).squaredNorm();
    }
    if (!(spread > 0)) return;
    for (size_t m = 0; m < map_pose_block_.size(); ++m) {
      if (map_pose_block_[m] < 0) continue;
      a_o.segment<6>(blocks_[map_pose_block_[m]].offset) =
          RotationVectorPerTangent().asDiagonal() *
          CenterJacobian(poses[m]).transpose() * (poses[m].Center() - mean) /
          spread;
    }
  } else {
    const auto& refined = calibration_.refined_points3D;
    if (refined.size() < 3) return;  // AnchorRefinedPointsToMap neither
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& [id, point] : refined) mean += point;
    mean /= refined.size();
    double spread = 0;
    for (const auto& [id, point] : refined) {
      spread += (point - mean).squaredNorm();
    }
    if (!(spread > 0)) return;
    for (size_t p = 0; p < points_.size(); ++p) {
      a_points[p] = (points_[p] - mean) / spread;
    }
  }
  // Right-hand side after eliminating the points.
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(num_o_ + num_c_);
  rhs.head(num_o_) = a_o;
  for (size_t p = 0; p < points_.size(); ++p) {
    solver_->EliminatePointVector(static_cast<int>(p), a_points[p], &rhs);
  }
  Eigen::VectorXd y_o = Eigen::VectorXd::Zero(num_o_);
  Eigen::VectorXd rhs_c = rhs.tail(num_c_);
  if (num_o_ > 0) {
    y_o = scale_o_.asDiagonal() *
          ldlt_o_.solve(scale_o_.asDiagonal() * rhs.head(num_o_));
    rhs_c -= r_oc_.transpose() * y_o;
  }
  const Eigen::VectorXd v_c = covariance_c_ * rhs_c;
  Eigen::VectorXd v = Eigen::VectorXd::Zero(num_o_ + num_c_);
  if (num_o_ > 0) v.head(num_o_) = y_o - x_oc_ * v_c;
  v.tail(num_c_) = v_c;
  double a_v = a_o.dot(v.head(num_o_));
  anchor_v_points_.assign(points_.size(), Eigen::Vector3d::Zero());
  for (size_t p = 0; p < points_.size(); ++p) {
    anchor_v_points_[p] =
        solver_->BackSubstitutePoint(static_cast<int>(p), a_points[p], v);
    a_v += a_points[p].dot(anchor_v_points_[p]);
  }
  anchor_v_ = v;
  const Eigen::VectorXd& n = scale_direction_c_;
  covariance_c_ +=
      -n * v_c.transpose() - v_c * n.transpose() + a_v * n * n.transpose();
}

// The between-framesets covariance over C (see the header): per cluster g
// (a frameset's rig images, or one map image) its score
//   s_g = sum_{k in g} rho'(s_k) J_k^T r_k
// over every free parameter, its influence d_g = (J^T J)^-1 s_g / mean(rho'
// + s rho'') on C by the same elimination as the covariance (points by
// their 3x3 blocks, then O through R_OO^-1 R_OC = x_oc_, then the gauge as
// held by the priors), the anchoring's scale taken out as in AnchorScale
// (d_C - n_C a^T d, a^T d = anchor_v_^T s_g), and
//   Cov_between = G/(G-1) sum_g d_g d_g^T.
// `unanchored`: the covariance over C before AnchorScale. The clusters run
// on all threads, each into its own d_g, summed in cluster order.
void UncertaintyProblem::BetweenFramesetsCovariance(
    const Eigen::MatrixXd& unanchored) {
  const int num_clusters =
      static_cast<int>(rig_from_world_.size() + map_cam_from_world_.size());
  std::vector<std::vector<int>> by_cluster(num_clusters);
  for (size_t o = 0; o < observations_.size(); ++o) {
    by_cluster[observations_[o].cluster].push_back(static_cast<int>(o));
  }
  // A frameset's priors of its velocity and acceleration are part of its
  // score, unweighted (no robust loss); its innovation cost's too, whose
  // gradient reaches the previous frameset's parameters: the innovations
  // are what the prior takes as independent.
  std::vector<std::vector<size_t>> priors_by_cluster(num_clusters);
  for (const auto& [frameset, residual] : translation_priors_) {
    priors_by_cluster[frameset].push_back(residual);
  }
  std::vector<int> clusters;
  for (int g = 0; g < num_clusters; ++g) {
    if (!by_cluster[g].empty()) clusters.push_back(g);
  }
  const int num_used = static_cast<int>(clusters.size());
  const double n = static_cast<double>(num_residuals_ / 2);
  const double mean_bread = sum_bread_ / n;
  if (num_used < kMinNumClusters || !(mean_bread > 0)) return;
  const double loss_b = options_.loss_scale_px * options_.loss_scale_px;
  const bool anchored = anchor_v_.size() == num_o_ + num_c_;
  std::vector<Eigen::VectorXd> influences(num_used);
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int g = 0; g < num_used; ++g) {
    Eigen::VectorXd score = Eigen::VectorXd::Zero(num_o_ + num_c_);
    std::vector<std::pair<int, Eigen::Vector3d>> point_scores;
    for (const int o : by_cluster[clusters[g]]) {
      const Observation& observation = observations_[o];
      const double u =
          solver_->Residual(observation.residual).squaredNorm() / loss_b;
      const Eigen::Vector3d point_score =
          solver_->AddGradient(observation.residual, 1 / (1 + u), &score);
      if (observation.point_index >= 0) {
        point_scores.emplace_back(observation.point_index, point_score);
      }
    }
    for (const size_t residual : priors_by_cluster[clusters[g]]) {
      solver_->AddGradient(residual, 1.0, &score);
    }
    double anchor = anchored ? anchor_v_.dot(score) : 0;
    Eigen::VectorXd reduced = score;
    std::stable_sort(
        point_scores.begin(), point_scores.end(),
        [](const auto& a, const auto& b) { return a.first < b.first; });
    for (size_t k = 0; k < point_scores.size();) {
      const int p = point_scores[k].first;
      Eigen::Vector3d point_score = Eigen::Vector3d::Zero();
      for (; k < point_scores.size() && point_scores[k].first == p; ++k) {
        point_score += point_scores[k].second;
      }
      solver_->EliminatePointVector(p, point_score, &reduced);
      if (anchored) anchor += anchor_v_points_[p].dot(point_score);
    }
    Eigen::VectorXd rhs_c = reduced.tail(num_c_);
    if (num_o_ > 0) rhs_c -= x_oc_.transpose() * reduced.head(num_o_);
    Eigen::VectorXd influence = unanchored * rhs_c;
    if (anchored) influence -= anchor * scale_direction_c_;
    influences[g] = influence / mean_bread;
  }
  cluster_covariance_c_ = Eigen::MatrixXd::Zero(num_c_, num_c_);
  for (const Eigen::VectorXd& influence : influences) {
    cluster_covariance_c_.selfadjointView<Eigen::Lower>().rankUpdate(influence);
  }
  cluster_covariance_c_ = cluster_covariance_c_.selfadjointView<Eigen::Lower>();
  cluster_covariance_c_ *= static_cast<double>(num_used) / (num_used - 1);
  num_clusters_ = num_used;
}

void UncertaintyProblem::FillProjection(int camera_index,
                                        const UncertaintyOptions& options,
                                        CameraUncertainty* uncertainty) const {
  const colmap::Camera& camera = calibration_.cameras[camera_index];
  ProjectionUncertainty& projection = uncertainty->projection;
  projection.depth = Median(distances_[camera_index]);
  projection.cols = std::max(1, options.grid_cols);
  projection.rows = std::max(
      1, static_cast<int>(std::lround(projection.cols *
                                      static_cast<double>(camera.Height()) /
                                      camera.Width())));
  projection.stddev_px.assign(projection.cols * projection.rows, kNaN);
  const auto* cost =
      dynamic_cast<const TangentJacobianCost*>(CostFor(camera.ModelId()));
  const int num_params = static_cast<int>(camera.NumParams());
  const Rigid3d& cam_from_rig = calibration_.cam_from_rig[camera_index];
  const Rigid3d rig_from_cam = cam_from_rig.Inverse();
  const PoseArray& cam_pose = cam_from_rig_[camera_index];
  Eigen::Matrix<double, 2, 6, Eigen::RowMajor> j_cam;  // over (d, t)
  std::vector<double> j_intrinsics(2 * num_params);
  std::vector<double> values;
  for (int row = 0; row < projection.rows; ++row) {
    for (int col = 0; col < projection.cols; ++col) {
      const Eigen::Vector2d pixel(
          (col + 0.5) * camera.Width() / projection.cols,
          (row + 0.5) * camera.Height() / projection.rows);
      const Eigen::Vector2d normalized = camera.ImageToWorld(pixel);
      const Eigen::Vector2d back = camera.WorldToImage(normalized);
      if (!normalized.allFinite() || !back.allFinite() ||
          (back - pixel).norm() > kMaxRoundTripErrorPx) {
        continue;
      }
      const Eigen::Vector3d point_in_rig =
          rig_from_cam *
          (projection.depth * normalized.homogeneous().normalized());
      const double* parameters[4] = {identity_.data(), cam_pose.data(),
                                     camera.ParamsData(), point_in_rig.data()};
      double* jacobians[4] = {nullptr, j_cam.data(), j_intrinsics.data(),
                              nullptr};
      double residual[2];
      if (!cost->EvaluateTangent(parameters, residual, jacobians)) continue;
      Eigen::MatrixXd jacobian(2, num_params + 6);
      for (int k = 0; k < num_params; ++k) {
        jacobian(0, k) = j_intrinsics[k];
        jacobian(1, k) = j_intrinsics[num_params + k];
      }
      // Over (w, t), w = 2 d.
      jacobian.rightCols<6>() =
          j_cam * RotationVectorPerTangent().cwiseInverse().asDiagonal();
      // The larger of the two estimates (see the header), each in its
      // worst direction.
      double stddev = 0;
      for (const Eigen::MatrixXd* matrix :
           {&uncertainty->covariance,
            &uncertainty->between_framesets_covariance}) {
        if (matrix->rows() != num_params + 6) continue;
        const Eigen::Matrix2d pixel_covariance =
            jacobian * *matrix * jacobian.transpose();
        stddev = std::max(
            stddev,
            std::sqrt(std::max(
                0.0,
                Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(pixel_covariance)
                    .eigenvalues()
                    .maxCoeff())));
      }
      projection.stddev_px[row * projection.cols + col] = stddev;
      values.push_back(stddev);
      if (stddev > projection.max_px || values.size() == 1) {
        projection.max_px = stddev;
        projection.max_at = pixel;
      }
    }
  }
  projection.median_px = Median(values);
}

void UncertaintyProblem::FillCameras(const UncertaintyOptions& options,
                                     CalibrationUncertainty* result) const {
  const double variance =
      result->effective_scale_px * result->effective_scale_px;
  const bool between = cluster_covariance_c_.rows() == num_c_ && num_c_ > 0;
  result->cameras.assign(calibration_.cameras.size(), CameraUncertainty());
  for (size_t c = 0; c < calibration_.cameras.size(); ++c) {
    if (distances_[c].empty()) continue;  // not in the adjustment
    CameraUncertainty& camera = result->cameras[c];
    camera.computed = true;
    const int num_params =
        static_cast<int>(calibration_.cameras[c].NumParams());
    // The C index of every entry of [params, w, t] (-1: held).
    std::vector<int> index(num_params + 6, -1);
    // d[params, w, t] / d(C coordinates) per entry (see
    // RotationVectorPerTangent).
    Eigen::VectorXd scale = Eigen::VectorXd::Ones(num_params + 6);
    if (intrinsics_block_[c] >= 0) {
      const int offset = blocks_[intrinsics_block_[c]].offset - num_o_;
      for (size_t k = 0; k < free_intrinsics_[c].size(); ++k) {
        index[free_intrinsics_[c][k]] = offset + static_cast<int>(k);
      }
    }
    if (extrinsics_block_[c] >= 0) {
      const int offset = blocks_[extrinsics_block_[c]].offset - num_o_;
      for (int k = 0; k < 6; ++k) index[num_params + k] = offset + k;
      scale.tail<6>() = RotationVectorPerTangent();
    }
    const int size = num_params + 6;
    camera.covariance = Eigen::MatrixXd::Zero(size, size);
    if (between) {
      camera.between_framesets_covariance = Eigen::MatrixXd::Zero(size, size);
    }
    std::vector<char> undetermined(size, 0);
    camera.determined = true;
    for (int i = 0; i < size; ++i) {
      if (index[i] < 0) continue;
      undetermined[i] = undetermined_c_[index[i]];
      camera.determined = camera.determined && !undetermined[i];
      for (int j = 0; j < size; ++j) {
        if (index[j] < 0) continue;
        camera.covariance(i, j) = variance * scale(i) * scale(j) *
                                  covariance_c_(index[i], index[j]);
        if (between) {
          camera.between_framesets_covariance(i, j) =
              scale(i) * scale(j) * cluster_covariance_c_(index[i], index[j]);
        }
      }
    }
    // The reported standard deviation of a linear function v^T x of [params,
    // w, t]: the larger of the two estimates (see the header).
    const auto larger = [&](const Eigen::MatrixXd& v) {
      double value = (v.transpose() * camera.covariance * v).trace();
      if (between) {
        value = std::max(
            value,
            (v.transpose() * camera.between_framesets_covariance * v).trace());
      }
      return std::sqrt(std::max(0.0, value));
    };
    const auto stddev = [&](int i) {
      if (undetermined[i]) return kNaN;
      return larger(Eigen::VectorXd::Unit(size, i));
    };
    for (int k = 0; k < size; ++k) {
      if (!between || index[k] < 0 || undetermined[k]) continue;
      const double noise = std::sqrt(std::max(0.0, camera.covariance(k, k)));
      const double spread = std::sqrt(
          std::max(0.0, camera.between_framesets_covariance(k, k)));
      if (noise > 0) {
        camera.between_framesets_factor =
            std::max(camera.between_framesets_factor, spread / noise);
      }
    }
    for (int k = 0; k < num_params; ++k) {
      camera.params_stddev.push_back(stddev(k));
    }
    const bool extrinsics_determined =
        std::none_of(undetermined.end() - 6, undetermined.end(),
                     [](char u) { return u != 0; });
    const double to_deg = 180 / M_PI;
    for (int k = 0; k < 3; ++k) {
      camera.rotation_axis_stddev_deg(k) = to_deg * stddev(num_params + k);
      camera.translation_stddev(k) = stddev(num_params + 3 + k);
    }
    // sqrt(trace Cov_w): the rotation rows of [params, w, t].
    Eigen::MatrixXd rotation_rows = Eigen::MatrixXd::Zero(size, 3);
    rotation_rows.block<3, 3>(num_params, 0).setIdentity();
    camera.rotation_stddev_deg =
        extrinsics_determined ? to_deg * larger(rotation_rows) : kNaN;
    const Eigen::Matrix<double, 3, 6> center_jacobian =
        CenterJacobian(calibration_.cam_from_rig[c]);
    for (int k = 0; k < 3; ++k) {
      Eigen::VectorXd row = Eigen::VectorXd::Zero(size);
      row.tail<6>() = center_jacobian.row(k).transpose();
      camera.center_in_rig_stddev(k) =
          extrinsics_determined ? larger(row) : kNaN;
    }
    // The time model's parameters: the larger of the two estimates.
    const auto time_stddev = [&](int block) {
      if (block < 0) return 0.0;
      const int k = blocks_[block].offset - num_o_;
      if (undetermined_c_[k]) return kNaN;
      double value = variance * covariance_c_(k, k);
      if (between) value = std::max(value, cluster_covariance_c_(k, k));
      return std::sqrt(std::max(0.0, value));
    };
    camera.time_offset_stddev_s = time_stddev(time_offset_block_[c]);
    camera.line_delay_stddev_s = time_stddev(line_delay_block_[c]);
    if (camera.determined)
      FillProjection(static_cast<int>(c), options, &camera);
  }
}

std::string UncertaintyProblem::Method() const {
  std::ostringstream method;
  method << "Covariance sigma_eff^2 (J^T J)^-1 of the final bundle "
            "adjustment at its result, over its "
         << num_rig_observations_ << " rig";
  if (num_map_observations_ > 0) {
    method << " and " << num_map_observations_ << " map";
  }
  method << " inlier observations; sigma_eff from the residuals (Huber's "
            "sandwich factor for the Cauchy loss, dof correction m/(m-p)); "
            "marginalized: rig poses";
  if (!points_.empty()) method << ", " << points_.size() << " refined points";
  if (options_.refine_map && num_map_observations_ > 0) {
    method << ", map image poses";
    if (options_.refine_map_intrinsics) method << " and intrinsics";
  }
  if (free_gauge_) {
    method << "; gauge: free (a similarity), the scale fixed as the result "
              "was anchored to the "
           << (options_.refine_map ? "input map's camera centres"
                                   : "map positions of the refined points")
           << ", whose uncertainty the translations include";
  } else {
    method << "; gauge: fixed by the "
           << (options_.refine_points ? "fixed map points or map image poses"
                                      : "fixed map points");
  }
  if (num_clusters_ > 0) {
    method << "; every standard deviation is the larger of that and the "
              "between-framesets covariance (cluster-robust sandwich over "
           << num_clusters_
           << " framesets and map images), which covers per-camera noise "
              "levels and errors shared within a frameset or image; neither "
              "covers errors every frameset shares (a fixed map's bias, a "
              "lens the model cannot follow)";
  } else {
    method << "; assumes independent Gaussian pixel noise of one level for "
              "all observations (fewer than 3 framesets and map images: no "
              "between-framesets estimate)";
  }
  return method.str();
}

bool UncertaintyProblem::Run(const UncertaintyOptions& options,
                             CalibrationUncertainty* result) {
  if (!SetUpTimeModel(&result->message)) return false;
  CollectObservations();
  if (observations_.empty()) {
    result->message = "no inlier observation";
    return false;
  }
  AssignBlocks();
  if (!BuildReducedSystem(&result->message)) return false;
  GatherResidualStatistics();
  num_parameters_ += num_o_ + num_c_ - (free_gauge_ ? 7 : 0);
  result->num_residuals = num_residuals_;
  result->num_parameters = num_parameters_;
  result->free_gauge = free_gauge_;
  result->method = Method();
  const int64_t redundancy = num_residuals_ - num_parameters_;
  if (redundancy <= 0) {
    result->message = "no redundancy (" + std::to_string(num_residuals_) +
                      " residuals for " + std::to_string(num_parameters_) +
                      " parameters): the uncertainty is undetermined";
    return false;
  }
  const double n = static_cast<double>(num_residuals_ / 2);
  const double dof = static_cast<double>(num_residuals_) / redundancy;
  result->residual_scale_px = std::sqrt(sum_squared_ / redundancy);
  result->effective_scale_px =
      std::sqrt(dof * (sum_meat_ / n) / std::pow(sum_bread_ / n, 2));
  AddGaugePriors();
  if (!Marginalize(result)) return false;
  const Eigen::MatrixXd unanchored = covariance_c_;
  if (free_gauge_) AnchorScale();
  BetweenFramesetsCovariance(unanchored);
  result->num_clusters = num_clusters_;
  result->method = Method();
  FillCameras(options, result);
  return true;
}

// The sizes the computation indexes by (AdjustRig's output has them).
bool ShapedLike(const RigDataset& dataset, const RigCalibration& calibration) {
  const size_t num_cameras = dataset.cameras.size();
  if (calibration.cameras.size() != num_cameras ||
      calibration.cam_from_rig.size() != num_cameras ||
      calibration.camera_calibrated.size() != num_cameras ||
      calibration.rig_from_world.size() != dataset.frameset_names.size() ||
      calibration.images.size() != dataset.images.size() ||
      dataset.reference_camera < 0 ||
      dataset.reference_camera >= static_cast<int>(num_cameras)) {
    return false;
  }
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    const RigImage& image = dataset.images[i];
    const size_t mask_size = calibration.images[i].inlier_mask.size();
    if (image.camera_index < 0 ||
        image.camera_index >= static_cast<int>(num_cameras) ||
        image.frameset_index < 0 ||
        image.frameset_index >=
            static_cast<int>(calibration.rig_from_world.size()) ||
        (mask_size != 0 && mask_size != image.correspondences.size())) {
      return false;
    }
  }
  return true;
}

}  // namespace

CalibrationUncertainty EstimateCalibrationUncertainty(
    const FinalBundleAdjustmentOptions& ba_options, const RigDataset& dataset,
    const RigCalibration& calibration, const UncertaintyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  CalibrationUncertainty result;
  if (!ShapedLike(dataset, calibration)) {
    result.message = "the calibration does not match the dataset";
  } else {
    // A map image's pose that the data do not determine (it sees a few
    // refined points, or points in a degenerate layout; the final
    // adjustment's damping, not the data, held it) makes the whole reduced
    // system singular: the image is left out and the uncertainty computed
    // again. Left out, not held: a held pose with its observations would pin
    // the free world (the map's gauge) to its few points. On the real EuRoC
    // pair one such map image left the uncertainty uncomputed. So is a
    // frameset whose observations do not determine its rig pose (a few
    // inliers: a 15 Hz helmet's last frameset kept 3 of its correspondences
    // when the time model's alternation diverged there, frameset_motion.h);
    // the calibration loses only that frameset's few observations.
    std::vector<char> left_out_map_images(dataset.map_images.size(), 0);
    std::vector<char> left_out_framesets(dataset.frameset_names.size(), 0);
    std::vector<std::string> map_image_names, frameset_names;
    for (int attempt = 0; attempt <= kMaxLeftOutPoses; ++attempt) {
      result = CalibrationUncertainty();
      UncertaintyProblem problem(ba_options, dataset, calibration,
                                 left_out_map_images, left_out_framesets);
      result.computed = problem.Run(options, &result);
      if (result.computed) break;
      const int map_image = problem.undetermined_map_image();
      const int frameset = problem.undetermined_frameset();
      if (map_image >= 0 && !left_out_map_images[map_image]) {
        left_out_map_images[map_image] = 1;
        map_image_names.push_back(dataset.map_images[map_image].name);
      } else if (frameset >= 0 && !left_out_framesets[frameset]) {
        left_out_framesets[frameset] = 1;
        frameset_names.push_back(dataset.frameset_names[frameset]);
      } else {
        break;
      }
    }
    const auto list = [](const std::vector<std::string>& names) {
      std::string text;
      for (const std::string& name : names) {
        text += (text.empty() ? "" : ", ") + name;
      }
      return text;
    };
    if (result.computed && !map_image_names.empty()) {
      result.method += "; the poses of " +
                       std::to_string(map_image_names.size()) +
                       " map image(s) that the data do not determine left "
                       "out (" + list(map_image_names) + ")";
    }
    if (result.computed && !frameset_names.empty()) {
      result.method += "; the rig poses of " +
                       std::to_string(frameset_names.size()) +
                       " frameset(s) that the data do not determine left "
                       "out with their observations (" +
                       list(frameset_names) + ")";
    }
  }
  if (!result.computed) result.cameras.clear();
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  return result;
}

// Thresholds (calibration_uncertainty.h):
//  - kLargeProjectionStddevPx = 1 px: keypoints are measured to about
//    0.3-1 px (SIFT on real images; 0.25 px RMS on the rendered demo), so a
//    calibration whose own 1-sigma error reaches a pixel somewhere is, there,
//    at least as large as the noise of one measurement and becomes the
//    dominant error of whatever projects through it.
//  - kPoorPrincipalPointStddevPx = 1 px: the 95 % interval (+-2 sigma) is then
//    4 px wide or more, as wide as a lens-sensor assembly's typical offset of
//    the principal point from the image centre, so the data hardly improve
//    on assuming the centre, while a principal point that wanders with the
//    noise drags the camera's rotation (1 px ~ 1/f rad) and distortion with
//    it. Holding it (refine_principal_point 0) then costs little.
//  - kFramesetsDisagreeFactor = 3: on maps with independent errors, and on
//    synthetic maps made like structure from motion (drift, noisy poses,
//    points triangulated through them), the between-framesets sigma is
//    within 1.5x of the noise sigma; on the real EuRoC pair it is 8-10x,
//    and that camera's rotation was 0.7 deg from the pattern calibration,
//    20 sigma of the noise covariance. Errors that every observation of a
//    frameset or map image shares then dominate, and a sandwich over a
//    few dozen clusters underestimates them.
std::vector<Diagnostic> UncertaintyDiagnostics(
    const RigDataset& dataset, const RigCalibration& calibration,
    const CalibrationUncertainty& uncertainty) {
  std::vector<Diagnostic> diagnostics;
  if (!uncertainty.computed) {
    Diagnostic diagnostic;
    diagnostic.level = Diagnostic::Level::kWarning;
    diagnostic.code = "undetermined_parameters";
    diagnostic.message =
        "the uncertainty of the calibration could not be "
        "computed: " +
        uncertainty.message;
    diagnostics.push_back(diagnostic);
    return diagnostics;
  }
  const auto format = [](double value, int precision) {
    std::ostringstream text;
    text << std::fixed << std::setprecision(precision) << value;
    return text.str();
  };
  for (size_t c = 0; c < uncertainty.cameras.size(); ++c) {
    const CameraUncertainty& camera = uncertainty.cameras[c];
    if (!camera.computed) continue;
    const std::string& name = dataset.cameras[c].name;
    const colmap::Camera& intrinsics = calibration.cameras[c];
    if (!camera.determined) {
      std::vector<std::string> names;
      // "fx, fy, cx, cy, k1, ...".
      std::vector<std::string> param_names;
      std::istringstream info(intrinsics.ParamsInfo());
      for (std::string param; std::getline(info, param, ',');) {
        param_names.push_back(param.substr(param.find_first_not_of(' ')));
      }
      for (size_t k = 0; k < camera.params_stddev.size(); ++k) {
        if (std::isnan(camera.params_stddev[k]) && k < param_names.size()) {
          names.push_back(param_names[k]);
        }
      }
      if (std::isnan(camera.rotation_stddev_deg)) {
        names.push_back("cam_from_rig");
      }
      std::string list;
      for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
      Diagnostic diagnostic;
      diagnostic.level = Diagnostic::Level::kWarning;
      diagnostic.code = "undetermined_parameters";
      diagnostic.message = name + ": the data do not determine " + list +
                           " (the adjustment's information matrix is "
                           "singular there): these values are arbitrary; add "
                           "framesets with other viewpoints or hold them";
      diagnostic.cameras = {static_cast<int>(c)};
      diagnostics.push_back(diagnostic);
    }
    double pp_stddev = 0;
    bool pp_undetermined = false;
    for (const size_t k : intrinsics.PrincipalPointIdxs()) {
      const double stddev = camera.params_stddev[k];
      pp_undetermined = pp_undetermined || std::isnan(stddev);
      if (!std::isnan(stddev)) pp_stddev = std::max(pp_stddev, stddev);
    }
    if (pp_undetermined || pp_stddev > kPoorPrincipalPointStddevPx) {
      const std::vector<size_t> pp = intrinsics.PrincipalPointIdxs();
      // The pipeline has added the model choice's spread
      // (model_choice_spread.h) before it diagnoses.
      bool pp_from_model_choice = false;
      for (const size_t k : pp) {
        pp_from_model_choice =
            pp_from_model_choice ||
            (k < camera.model_choice_stddev.size() &&
             camera.model_choice_stddev[k] > kPoorPrincipalPointStddevPx);
      }
      Diagnostic diagnostic;
      diagnostic.level = Diagnostic::Level::kWarning;
      diagnostic.code = "poorly_determined_principal_point";
      diagnostic.message =
          name + ": the principal point is poorly determined (" +
          (pp_undetermined
               ? std::string("undetermined")
               : "1-sigma " + format(camera.params_stddev[pp[0]], 2) +
                     " px in x, " + format(camera.params_stddev[pp[1]], 2) +
                     " px in y") +
          ", above " + format(kPoorPrincipalPointStddevPx, 1) + " px" +
          (pp_from_model_choice
               ? std::string(", from the model choice: another camera "
                             "model fits as well and puts it elsewhere")
               : std::string()) +
          "): hold it with --RigCalibrator.refine_principal_point 0 (at "
          "its initial value, the image centre unless given), or add "
          "framesets whose features cover the whole image";
      diagnostic.cameras = {static_cast<int>(c)};
      diagnostics.push_back(diagnostic);
    }
    const ProjectionUncertainty& projection = camera.projection;
    if (camera.determined && projection.max_px > kLargeProjectionStddevPx) {
      Diagnostic diagnostic;
      diagnostic.level = Diagnostic::Level::kWarning;
      diagnostic.code = "large_projection_uncertainty";
      diagnostic.message =
          name + ": the 1-sigma projection uncertainty reaches " +
          format(projection.max_px, 2) + " px at pixel (" +
          format(projection.max_at.x(), 0) + ", " +
          format(projection.max_at.y(), 0) + ") (median " +
          format(projection.median_px, 2) + " px over the image, above " +
          format(kLargeProjectionStddevPx, 1) +
          " px): the data determine this camera's projection poorly there; "
          "add framesets whose features reach that part of the image";
      diagnostic.cameras = {static_cast<int>(c)};
      diagnostics.push_back(diagnostic);
    }
    if (camera.between_framesets_factor > kFramesetsDisagreeFactor) {
      Diagnostic diagnostic;
      diagnostic.level = Diagnostic::Level::kWarning;
      diagnostic.code = "framesets_disagree";
      diagnostic.message =
          name + ": the framesets and map images disagree " +
          format(camera.between_framesets_factor, 1) +
          "x more than the pixel noise explains (above " +
          format(kFramesetsDisagreeFactor, 1) +
          "x): errors shared by the observations of one frameset or map "
          "image (the map's own errors, cameras not triggered together, a "
          "lens the model does not follow) dominate this camera's "
          "calibration, and its sigma, taken from their spread, may still "
          "be too small; compare with a calibration from other framesets";
      diagnostic.cameras = {static_cast<int>(c)};
      diagnostics.push_back(diagnostic);
    }
  }
  return diagnostics;
}

}  // namespace rig_calibrator
