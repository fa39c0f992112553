#include "src/calibration/calibration_uncertainty.h"

#include <colmap/base/camera_models.h>
#include <colmap/util/math.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
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

#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/pipeline_report.h"
#include "src/geometry/rig_reprojection_cost.h"
#include "src/rig/rig_dataset.h"

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
// At most this many map images whose poses the data do not determine are
// left out before the uncertainty is given up
// (EstimateCalibrationUncertainty).
constexpr int kMaxHeldMapImages = 20;
// A pixel whose unprojection does not project back within this distance is
// where the estimated model is not invertible: no projection uncertainty.
constexpr double kMaxRoundTripErrorPx = 0.01;

using PoseArray = std::array<double, 7>;  // [qw, qx, qy, qz, tx, ty, tz]

PoseArray ToArray(const Rigid3d& pose) {
  return {pose.rotation.w(),   pose.rotation.x(),    pose.rotation.y(),
          pose.rotation.z(),   pose.translation.x(), pose.translation.y(),
          pose.translation.z()};
}

// dq'/dw at w = 0 for q' = Exp(w) q (w a rotation vector in the frame the
// rotation maps to), q = (w, v): with Exp(w) = (1, w/2) to first order,
// (0, w) q = (-w.v, q_w w + w x v), so dq'/dw = 1/2 [-v^T; q_w I - [v]x].
Eigen::Matrix<double, 4, 3> QuaternionTangent(const double* q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  Eigen::Matrix<double, 4, 3> tangent;
  tangent << -x, -y, -z, w, z, -y, -z, w, x, y, -x, w;
  return 0.5 * tangent;
}

using RowMajor2x7 = Eigen::Matrix<double, 2, 7, Eigen::RowMajor>;

// The 2x6 Jacobian over (w, t) of a pose block from its 2x7 one over
// (q, t).
Eigen::Matrix<double, 2, 6> PoseTangentJacobian(const RowMajor2x7& jacobian,
                                                const double* pose) {
  Eigen::Matrix<double, 2, 6> tangent;
  tangent.leftCols<3>() = jacobian.leftCols<4>() * QuaternionTangent(pose);
  tangent.rightCols<3>() = jacobian.rightCols<3>();
  return tangent;
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
  const double* rig_pose = nullptr;
  const double* cam_pose = nullptr;
  const double* params = nullptr;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector2d observed = Eigen::Vector2d::Zero();
  int point_index = -1;  // into the refined points; -1: fixed point
  // Blocks of the reduced system (-1: held constant).
  int rig_block = -1, cam_block = -1, intrinsics_block = -1;
  const std::vector<int>* free_intrinsics = nullptr;
  int rig_camera = -1;  // the rig camera, -1 for a map image
  // The cluster of the between-framesets covariance: the frameset of a rig
  // image, num_framesets + m for map image m.
  int cluster = -1;
};

// One observation evaluated (UncertaintyProblem::EvaluateObservation).
struct ObservationJacobian {
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();
  std::vector<std::pair<int, Eigen::MatrixXd>> entries;
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> j_point;
  std::vector<double> j_intrinsics;  // scratch: over all the model's params
};

// A parameter block of the reduced system: O (nuisance: rig poses, map
// poses, map intrinsics) first, then C (rig intrinsics and cam_from_rig).
struct Block {
  int offset = 0;
  int dim = 0;
};

// What a refined point couples: its 3x3 information and, per reduced block
// it is observed through, the 3 x dim cross term.
struct PointTerms {
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  std::vector<std::pair<int, Eigen::MatrixXd>> cross;
  Eigen::Matrix3d pseudo_inverse = Eigen::Matrix3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();

  Eigen::MatrixXd& Cross(int block, int dim) {
    for (auto& [b, matrix] : cross) {
      if (b == block) return matrix;
    }
    cross.emplace_back(block, Eigen::MatrixXd::Zero(3, dim));
    return cross.back().second;
  }
};

// The symmetric reduced system as dense blocks (upper triangle, b1 <= b2).
class BlockMatrix {
 public:
  explicit BlockMatrix(const std::vector<Block>& blocks) : blocks_(blocks) {}

  void Add(int b1, int b2, const Eigen::MatrixXd& value) {
    if (b1 > b2) {
      Add(b2, b1, value.transpose());
      return;
    }
    const uint64_t key = static_cast<uint64_t>(b1) * blocks_.size() + b2;
    auto it = entries_.find(key);
    if (it == entries_.end()) {
      it = entries_
               .emplace(key,
                        Eigen::MatrixXd::Zero(blocks_[b1].dim, blocks_[b2].dim))
               .first;
    }
    it->second += value;
  }

  // Adds every block of `other` (over the same blocks).
  void AddAll(const BlockMatrix& other) {
    for (const auto& [key, value] : other.entries_) {
      auto it = entries_.find(key);
      if (it == entries_.end()) {
        entries_.emplace(key, value);
      } else {
        it->second += value;
      }
    }
  }

  // The stored block (b1 <= b2), or null.
  const Eigen::MatrixXd* Get(int b1, int b2) const {
    const auto it =
        entries_.find(static_cast<uint64_t>(b1) * blocks_.size() + b2);
    return it == entries_.end() ? nullptr : &it->second;
  }

  // Calls f(b1, b2, block) for every stored block (b1 <= b2).
  template <typename F>
  void ForEach(F f) const {
    for (const auto& [key, value] : entries_) {
      f(static_cast<int>(key / blocks_.size()),
        static_cast<int>(key % blocks_.size()), value);
    }
  }

 private:
  const std::vector<Block>& blocks_;
  std::unordered_map<uint64_t, Eigen::MatrixXd> entries_;
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

Eigen::Matrix3d PointPseudoInverse(const Eigen::Matrix3d& information,
                                   int* rank) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(information);
  const double max_eigenvalue = eigen.eigenvalues().maxCoeff();
  Eigen::Matrix3d inverse = Eigen::Matrix3d::Zero();
  *rank = 0;
  for (int k = 0; k < 3; ++k) {
    if (eigen.eigenvalues()(k) > 1e-12 * max_eigenvalue) {
      const Eigen::Vector3d direction = eigen.eigenvectors().col(k);
      inverse += direction * direction.transpose() / eigen.eigenvalues()(k);
      ++*rank;
    }
  }
  return inverse;
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

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  return values[middle];
}

// The reduced problem of one calibration and its solution.
class UncertaintyProblem {
 public:
  // held_map_images: per map image, left out (see
  // EstimateCalibrationUncertainty); empty: none.
  UncertaintyProblem(const FinalBundleAdjustmentOptions& ba_options,
                     const RigDataset& dataset,
                     const RigCalibration& calibration,
                     const std::vector<char>& held_map_images)
      : options_(ba_options),
        dataset_(dataset),
        calibration_(calibration),
        held_map_images_(held_map_images) {}

  bool Run(const UncertaintyOptions& options, CalibrationUncertainty* result);
  // After a Run that failed on a singular reduced system: the map image
  // whose pose held the smallest pivot, -1 when it was not a map pose.
  int undetermined_map_image() const { return undetermined_map_image_; }

 private:
  void CollectObservations();
  int AddBlock(int dim, std::vector<int>* slot, int index);
  void AssignBlocks();
  bool Accumulate();
  struct AccumulationChunk;
  bool EvaluateObservation(const Observation& observation,
                           ObservationJacobian* out) const;
  void AccumulateObservation(const Observation& observation, PointTerms* point,
                             AccumulationChunk* chunk) const;
  void EliminatePoint(PointTerms* point, AccumulationChunk* chunk) const;
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
  std::vector<char> held_map_images_;
  int undetermined_map_image_ = -1;
  PoseArray identity_ = {1, 0, 0, 0, 0, 0, 0};
  std::vector<std::vector<int>> free_intrinsics_;  // per rig camera
  std::vector<int> all_map_intrinsics_;            // 0..n-1 of a map camera
  std::vector<std::vector<int>> map_free_intrinsics_;
  std::vector<Observation> observations_;
  std::vector<int64_t> point_ids_;  // refined points in the problem
  std::unordered_map<int64_t, int> point_index_;
  std::vector<PointTerms> points_;
  int num_rig_observations_ = 0, num_map_observations_ = 0;
  bool has_fixed_points_ = false;
  bool free_gauge_ = false;

  // Reduced blocks and, per parameter owner, its block (-1: none).
  std::vector<Block> blocks_;
  std::vector<int> rig_pose_block_, map_pose_block_, map_intrinsics_block_,
      intrinsics_block_, extrinsics_block_;
  int num_o_ = 0, num_c_ = 0;  // scalar dimensions of O and C
  int num_o_blocks_ = 0;       // blocks [0, num_o_blocks_) are O
  std::unique_ptr<BlockMatrix> reduced_;

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
  }
  const auto point_index = [&](int64_t point3D_id) {
    const auto [it, inserted] =
        point_index_.emplace(point3D_id, static_cast<int>(point_ids_.size()));
    if (inserted) point_ids_.push_back(point3D_id);
    return it->second;
  };
  const bool refine_points = options_.refine_points;
  for (size_t i = 0; i < dataset_.images.size(); ++i) {
    const RigImage& image = dataset_.images[i];
    const int c = image.camera_index;
    if (!calibration_.camera_calibrated[c] ||
        !calibration_.rig_from_world[image.frameset_index]) {
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
      observation.params = calibration_.cameras[c].ParamsData();
      observation.observed = correspondence.point2D;
      observation.rig_camera = c;
      observation.free_intrinsics = &free_intrinsics_[c];
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
      // Blocks are assigned later; remember the owners in the block fields.
      observation.rig_block = image.frameset_index;
      observation.cluster = image.frameset_index;
      observation.cam_block = c;
      observation.intrinsics_block = c;
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
    }
    for (size_t m = 0; m < dataset_.map_images.size(); ++m) {
      if (m < held_map_images_.size() && held_map_images_[m]) continue;
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
        observation.params = camera.ParamsData();
        observation.observed = map_observation.point2D;
        observation.point = refined->second;
        observation.point_index = point_index(map_observation.point3D_id);
        observation.rig_block = static_cast<int>(m);
        observation.cluster =
            static_cast<int>(rig_from_world_.size() + m);
        observation.intrinsics_block = image.camera_index;
        observation.free_intrinsics = &map_free_intrinsics_[image.camera_index];
        observations_.push_back(observation);
        ++num_map_observations_;
        has_fixed_points_ = has_fixed_points_ || !options_.refine_map;
      }
    }
  }
  free_gauge_ =
      refine_points && options_.refine_rig_poses && !has_fixed_points_;
  points_.resize(point_ids_.size());
  for (size_t p = 0; p < point_ids_.size(); ++p) {
    points_[p].position = calibration_.refined_points3D.at(point_ids_[p]);
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
// (rig poses, map poses, map intrinsics), then C (per rig camera its
// intrinsics, then its cam_from_rig), and turns the owner indices that
// CollectObservations left in the observations into block ids.
void UncertaintyProblem::AssignBlocks() {
  const int num_cameras = static_cast<int>(calibration_.cameras.size());
  rig_pose_block_.assign(rig_from_world_.size(), -1);
  map_pose_block_.assign(map_cam_from_world_.size(), -1);
  map_intrinsics_block_.assign(map_free_intrinsics_.size(), -1);
  intrinsics_block_.assign(num_cameras, -1);
  extrinsics_block_.assign(num_cameras, -1);
  std::vector<char> camera_observed(num_cameras, 0);
  for (Observation& observation : observations_) {
    if (observation.rig_camera >= 0) {
      if (options_.refine_rig_poses) {
        observation.rig_block =
            AddBlock(6, &rig_pose_block_, observation.rig_block);
      } else {
        observation.rig_block = -1;
      }
      camera_observed[observation.rig_camera] = 1;
    } else {
      const int map_camera = observation.intrinsics_block;
      observation.rig_block =
          options_.refine_map
              ? AddBlock(6, &map_pose_block_, observation.rig_block)
              : -1;
      observation.intrinsics_block =
          options_.refine_map && options_.refine_map_intrinsics
              ? AddBlock(
                    static_cast<int>(map_free_intrinsics_[map_camera].size()),
                    &map_intrinsics_block_, map_camera)
              : -1;
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
  for (Observation& observation : observations_) {
    if (observation.rig_camera < 0) continue;
    const int c = observation.rig_camera;
    observation.cam_block = extrinsics_block_[c];
    observation.intrinsics_block = intrinsics_block_[c];
  }
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

// What one chunk of the observations adds to the reduced system and the
// residual statistics (Accumulate). Aligned to a cache line, so that two
// threads' chunks never share one.
struct alignas(64) UncertaintyProblem::AccumulationChunk {
  std::unique_ptr<BlockMatrix> reduced;
  double sum_squared = 0, sum_meat = 0, sum_bread = 0;
  int64_t num_used = 0;
  int64_t num_point_parameters = 0;            // ranks of the eliminated points
  std::vector<std::vector<double>> distances;  // per rig camera
  ObservationJacobian evaluated;               // scratch
};

int UncertaintyProblem::NumThreads() const {
  return options_.num_threads > 0
             ? options_.num_threads
             : std::max(1,
                        static_cast<int>(std::thread::hardware_concurrency()));
}

// The residual r = projected - observed of one observation and its Jacobian
// over the reduced blocks it varies (`entries`: block, 2 x dim in the
// blocks' tangent spaces) and over its point. False for a point behind its
// camera (not an inlier of the adjustment).
bool UncertaintyProblem::EvaluateObservation(const Observation& observation,
                                             ObservationJacobian* out) const {
  const ceres::CostFunction* cost = costs_.at(observation.model_id).get();
  const int num_params = cost->parameter_block_sizes()[2];
  RowMajor2x7 j_rig, j_cam;
  out->j_intrinsics.resize(2 * num_params);
  const double* parameters[4] = {observation.rig_pose, observation.cam_pose,
                                 observation.params, observation.point.data()};
  double* jacobians[4] = {j_rig.data(), j_cam.data(),
                          out->j_intrinsics.data(), out->j_point.data()};
  double projected[2];
  if (!cost->Evaluate(parameters, projected, jacobians)) return false;
  out->residual = Eigen::Vector2d(projected[0], projected[1]) -
                  observation.observed;
  std::vector<std::pair<int, Eigen::MatrixXd>>& entries = out->entries;
  entries.clear();
  if (observation.rig_block >= 0) {
    entries.emplace_back(observation.rig_block,
                         PoseTangentJacobian(j_rig, observation.rig_pose));
  }
  if (observation.cam_block >= 0) {
    entries.emplace_back(observation.cam_block,
                         PoseTangentJacobian(j_cam, observation.cam_pose));
  }
  if (observation.intrinsics_block >= 0) {
    const std::vector<int>& free = *observation.free_intrinsics;
    Eigen::MatrixXd jacobian(2, free.size());
    for (size_t k = 0; k < free.size(); ++k) {
      jacobian(0, k) = out->j_intrinsics[free[k]];
      jacobian(1, k) = out->j_intrinsics[num_params + free[k]];
    }
    entries.emplace_back(observation.intrinsics_block, jacobian);
  }
  return true;
}

// J^T J of one observation into the chunk's reduced blocks and the terms of
// its refined point (`point`, null for a fixed one), and its residual
// statistics (see the header).
void UncertaintyProblem::AccumulateObservation(const Observation& observation,
                                               PointTerms* point,
                                               AccumulationChunk* chunk) const {
  ObservationJacobian& evaluated = chunk->evaluated;
  if (!EvaluateObservation(observation, &evaluated)) return;
  ++chunk->num_used;
  const double loss_b = options_.loss_scale_px * options_.loss_scale_px;
  const double s = evaluated.residual.squaredNorm();
  const double u = s / loss_b;
  chunk->sum_squared += s;
  chunk->sum_meat += s / 2 / ((1 + u) * (1 + u));  // rho'^2 s / 2
  chunk->sum_bread += 1 / ((1 + u) * (1 + u));     // rho' + s rho''
  if (observation.rig_camera >= 0) {
    chunk->distances[observation.rig_camera].push_back(
        Transform(observation.rig_pose, observation.cam_pose, observation.point)
            .norm());
  }
  const std::vector<std::pair<int, Eigen::MatrixXd>>& entries =
      evaluated.entries;
  const Eigen::Matrix<double, 2, 3, Eigen::RowMajor>& j_point =
      evaluated.j_point;
  for (size_t i = 0; i < entries.size(); ++i) {
    for (size_t j = i; j < entries.size(); ++j) {
      chunk->reduced->Add(entries[i].first, entries[j].first,
                          entries[i].second.transpose() * entries[j].second);
    }
  }
  if (point != nullptr) {
    point->information += j_point.transpose() * j_point;
    for (const auto& [block, jacobian] : entries) {
      point->Cross(block, blocks_[block].dim) += j_point.transpose() * jacobian;
    }
  }
}

// The Schur complement of one point: R -= W^T H_pp^+ W. A point direction
// without information (e.g. along the ray of a point seen once) has none in
// W either, so the pseudo-inverse is exact.
void UncertaintyProblem::EliminatePoint(PointTerms* point,
                                        AccumulationChunk* chunk) const {
  int rank = 0;
  point->pseudo_inverse = PointPseudoInverse(point->information, &rank);
  chunk->num_point_parameters += rank;
  for (size_t i = 0; i < point->cross.size(); ++i) {
    const Eigen::MatrixXd left =
        point->cross[i].second.transpose() * point->pseudo_inverse;
    for (size_t j = i; j < point->cross.size(); ++j) {
      chunk->reduced->Add(point->cross[i].first, point->cross[j].first,
                          -left * point->cross[j].second);
    }
  }
}

// The reduced system with the points eliminated, and the residual
// statistics. The observations are taken point by point, in kNumChunks
// chunks of whole points (the fixed points' observations last), on all
// threads: a point is eliminated by its chunk as soon as its observations
// are in, and the chunks' sums are added in chunk order, so the result does
// not depend on the thread count.
bool UncertaintyProblem::Accumulate() {
  constexpr size_t kNumChunks = 8;
  // The cost functions first: the threads only read the cache.
  for (const Observation& observation : observations_) {
    if (CostFor(observation.model_id) == nullptr) return false;
  }
  // Observations by point (a stable counting sort), fixed points last.
  const int num_points = static_cast<int>(points_.size());
  std::vector<size_t> point_begin(num_points + 2, 0);
  for (const Observation& observation : observations_) {
    ++point_begin[(observation.point_index < 0 ? num_points
                                               : observation.point_index) +
                  1];
  }
  for (int p = 0; p <= num_points; ++p) point_begin[p + 1] += point_begin[p];
  std::vector<size_t> order(observations_.size());
  std::vector<size_t> next(point_begin.begin(), point_begin.end() - 1);
  for (size_t o = 0; o < observations_.size(); ++o) {
    const int p = observations_[o].point_index;
    order[next[p < 0 ? num_points : p]++] = o;
  }
  // Chunks [first, end) of `order`: whole points, about equal sizes.
  const size_t target =
      std::max<size_t>(1, (order.size() + kNumChunks - 1) / kNumChunks);
  std::vector<std::pair<size_t, size_t>> ranges;
  size_t first = 0;
  for (int p = 0; p < num_points; ++p) {
    if (point_begin[p + 1] - first >= target) {
      ranges.emplace_back(first, point_begin[p + 1]);
      first = point_begin[p + 1];
    }
  }
  if (point_begin[num_points] > first) {
    ranges.emplace_back(first, point_begin[num_points]);
  }
  for (first = point_begin[num_points]; first < order.size(); first += target) {
    ranges.emplace_back(first, std::min(order.size(), first + target));
  }

  std::vector<AccumulationChunk> chunks(ranges.size());
  const int num_chunks = static_cast<int>(chunks.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int c = 0; c < num_chunks; ++c) {
    AccumulationChunk& chunk = chunks[c];
    chunk.reduced = std::make_unique<BlockMatrix>(blocks_);
    chunk.distances.assign(distances_.size(), {});
    for (size_t k = ranges[c].first; k < ranges[c].second; ++k) {
      const Observation& observation = observations_[order[k]];
      const int p = observation.point_index;
      AccumulateObservation(observation, p >= 0 ? &points_[p] : nullptr,
                            &chunk);
      if (p >= 0 && k + 1 == point_begin[p + 1]) {
        EliminatePoint(&points_[p], &chunk);
      }
    }
  }
  reduced_ = std::make_unique<BlockMatrix>(blocks_);
  int64_t num_used = 0;
  for (AccumulationChunk& chunk : chunks) {
    reduced_->AddAll(*chunk.reduced);
    chunk.reduced.reset();
    sum_squared_ += chunk.sum_squared;
    sum_meat_ += chunk.sum_meat;
    sum_bread_ += chunk.sum_bread;
    num_used += chunk.num_used;
    num_parameters_ += chunk.num_point_parameters;
    for (size_t camera = 0; camera < distances_.size(); ++camera) {
      distances_[camera].insert(distances_[camera].end(),
                                chunk.distances[camera].begin(),
                                chunk.distances[camera].end());
    }
  }
  num_residuals_ = 2 * num_used;
  return true;
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
  const int first_block = rig_pose_block_[first];
  const Eigen::MatrixXd* diagonal = reduced_->Get(first_block, first_block);
  const double weight =
      diagonal != nullptr && diagonal->trace() > 0 ? diagonal->trace() / 6 : 1;
  reduced_->Add(first_block, first_block,
                weight * Eigen::MatrixXd::Identity(6, 6));
  if (scale_direction_c_.norm() > 0) {
    // lambda n n^T / |n|^2 over the cam_from_rig blocks.
    const double norm2 = scale_direction_c_.squaredNorm();
    for (size_t c1 = 0; c1 < extrinsics_block_.size(); ++c1) {
      for (size_t c2 = c1; c2 < extrinsics_block_.size(); ++c2) {
        const int b1 = extrinsics_block_[c1], b2 = extrinsics_block_[c2];
        if (b1 < 0 || b2 < 0) continue;
        const Eigen::VectorXd n1 =
            scale_direction_c_.segment(blocks_[b1].offset - num_o_, 6);
        const Eigen::VectorXd n2 =
            scale_direction_c_.segment(blocks_[b2].offset - num_o_, 6);
        reduced_->Add(b1, b2, weight * n1 * n2.transpose() / norm2);
      }
    }
  } else if (farthest >= 0) {
    // Scaling about the first rig centre c*: t_Q of rig pose Q moves by
    // -R_Q (c_Q - c*).
    const Rigid3d& pose = *calibration_.rig_from_world[farthest];
    Eigen::VectorXd direction = Eigen::VectorXd::Zero(6);
    direction.tail<3>() =
        -(pose.RotationMatrix() *
          (pose.Center() - calibration_.rig_from_world[first]->Center()))
             .normalized();
    const int block = rig_pose_block_[farthest];
    reduced_->Add(block, block, weight * direction * direction.transpose());
  }
}

// Covariance over C of the reduced system: S_C = R_CC - R_CO R_OO^-1 R_OC,
// R_OO by a sparse LDL^T factorization of its Jacobi-scaled form.
bool UncertaintyProblem::Marginalize(CalibrationUncertainty* result) {
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::VectorXd diagonal_o = Eigen::VectorXd::Zero(num_o_);
  r_oc_ = Eigen::MatrixXd::Zero(num_o_, num_c_);
  Eigen::MatrixXd r_cc = Eigen::MatrixXd::Zero(num_c_, num_c_);
  reduced_->ForEach([&](int b1, int b2, const Eigen::MatrixXd& value) {
    const int o1 = blocks_[b1].offset, o2 = blocks_[b2].offset;
    if (b2 < num_o_blocks_) {
      for (int i = 0; i < value.rows(); ++i) {
        for (int j = 0; j < value.cols(); ++j) {
          triplets.emplace_back(o1 + i, o2 + j, value(i, j));
          if (b1 != b2) triplets.emplace_back(o2 + j, o1 + i, value(i, j));
        }
      }
      if (b1 == b2) diagonal_o.segment(o1, value.rows()) = value.diagonal();
    } else if (b1 < num_o_blocks_) {
      r_oc_.block(o1, o2 - num_o_, value.rows(), value.cols()) = value;
    } else {
      r_cc.block(o1 - num_o_, o2 - num_o_, value.rows(), value.cols()) = value;
      if (b1 != b2) {
        r_cc.block(o2 - num_o_, o1 - num_o_, value.cols(), value.rows()) =
            value.transpose();
      }
    }
  });
  Eigen::MatrixXd schur = r_cc;
  if (num_o_ > 0) {
    if (!(diagonal_o.minCoeff() > 0)) {
      result->message =
          "a rig or map pose has no information (no observation constrains "
          "it): the uncertainty is undetermined";
      return false;
    }
    scale_o_ = diagonal_o.cwiseSqrt().cwiseInverse();
    for (Eigen::Triplet<double>& t : triplets) {
      t = Eigen::Triplet<double>(
          t.row(), t.col(), t.value() * scale_o_(t.row()) * scale_o_(t.col()));
    }
    Eigen::SparseMatrix<double> r_oo(num_o_, num_o_);
    r_oo.setFromTriplets(triplets.begin(), triplets.end());
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
          for (size_t m = 0; m < map_pose_block_.size(); ++m) {
            const int block = map_pose_block_[m];
            if (block >= 0 && i >= blocks_[block].offset &&
                i < blocks_[block].offset + blocks_[block].dim) {
              undetermined_map_image_ = static_cast<int>(m);
            }
          }
          break;
        }
      }
      return false;
    }
    x_oc_ =
        scale_o_.asDiagonal() * ldlt_o_.solve(scale_o_.asDiagonal() * r_oc_);
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
      a_points[p] = (points_[p].position - mean) / spread;
    }
  }
  // Right-hand side after eliminating the points.
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(num_o_ + num_c_);
  rhs.head(num_o_) = a_o;
  for (size_t p = 0; p < points_.size(); ++p) {
    const Eigen::Vector3d pa = points_[p].pseudo_inverse * a_points[p];
    for (const auto& [block, cross] : points_[p].cross) {
      rhs.segment(blocks_[block].offset, blocks_[block].dim) -=
          cross.transpose() * pa;
    }
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
    Eigen::Vector3d residual = a_points[p];
    for (const auto& [block, cross] : points_[p].cross) {
      residual -= cross * v.segment(blocks_[block].offset, blocks_[block].dim);
    }
    anchor_v_points_[p] = points_[p].pseudo_inverse * residual;
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
    ObservationJacobian evaluated;
    for (const int o : by_cluster[clusters[g]]) {
      const Observation& observation = observations_[o];
      if (!EvaluateObservation(observation, &evaluated)) continue;
      const double u = evaluated.residual.squaredNorm() / loss_b;
      const Eigen::Vector2d weighted = evaluated.residual / (1 + u);
      for (const auto& [block, jacobian] : evaluated.entries) {
        score.segment(blocks_[block].offset, blocks_[block].dim) +=
            jacobian.transpose() * weighted;
      }
      if (observation.point_index >= 0) {
        point_scores.emplace_back(observation.point_index,
                                  evaluated.j_point.transpose() * weighted);
      }
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
      const Eigen::Vector3d solved = points_[p].pseudo_inverse * point_score;
      for (const auto& [block, cross] : points_[p].cross) {
        reduced.segment(blocks_[block].offset, blocks_[block].dim) -=
            cross.transpose() * solved;
      }
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
  ceres::CostFunction* cost = CostFor(camera.ModelId());
  const int num_params = static_cast<int>(camera.NumParams());
  const Rigid3d& cam_from_rig = calibration_.cam_from_rig[camera_index];
  const Rigid3d rig_from_cam = cam_from_rig.Inverse();
  const PoseArray& cam_pose = cam_from_rig_[camera_index];
  RowMajor2x7 j_rig, j_cam;
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> j_point;
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
      double* jacobians[4] = {j_rig.data(), j_cam.data(), j_intrinsics.data(),
                              j_point.data()};
      double residual[2];
      if (!cost->Evaluate(parameters, residual, jacobians)) continue;
      Eigen::MatrixXd jacobian(2, num_params + 6);
      for (int k = 0; k < num_params; ++k) {
        jacobian(0, k) = j_intrinsics[k];
        jacobian(1, k) = j_intrinsics[num_params + k];
      }
      jacobian.rightCols<6>() = PoseTangentJacobian(j_cam, cam_pose.data());
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
    if (intrinsics_block_[c] >= 0) {
      const int offset = blocks_[intrinsics_block_[c]].offset - num_o_;
      for (size_t k = 0; k < free_intrinsics_[c].size(); ++k) {
        index[free_intrinsics_[c][k]] = offset + static_cast<int>(k);
      }
    }
    if (extrinsics_block_[c] >= 0) {
      const int offset = blocks_[extrinsics_block_[c]].offset - num_o_;
      for (int k = 0; k < 6; ++k) index[num_params + k] = offset + k;
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
        camera.covariance(i, j) = variance * covariance_c_(index[i], index[j]);
        if (between) {
          camera.between_framesets_covariance(i, j) =
              cluster_covariance_c_(index[i], index[j]);
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
  CollectObservations();
  if (observations_.empty()) {
    result->message = "no inlier observation";
    return false;
  }
  AssignBlocks();
  if (!Accumulate()) {
    result->message = "a camera model without a cost function";
    return false;
  }
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
    // pair one such map image left the uncertainty uncomputed.
    std::vector<char> held(dataset.map_images.size(), 0);
    std::vector<std::string> held_names;
    for (int attempt = 0; attempt <= kMaxHeldMapImages; ++attempt) {
      result = CalibrationUncertainty();
      UncertaintyProblem problem(ba_options, dataset, calibration, held);
      result.computed = problem.Run(options, &result);
      const int map_image = problem.undetermined_map_image();
      if (result.computed || map_image < 0 || held[map_image]) break;
      held[map_image] = 1;
      held_names.push_back(dataset.map_images[map_image].name);
    }
    if (result.computed && !held_names.empty()) {
      std::string names;
      for (const std::string& name : held_names) {
        names += (names.empty() ? "" : ", ") + name;
      }
      result.method += "; the poses of " + std::to_string(held_names.size()) +
                       " map image(s) that the data do not determine left "
                       "out (" + names + ")";
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
          ", above " + format(kPoorPrincipalPointStddevPx, 1) +
          " px): hold it with --RigCalibrator.refine_principal_point 0 (at "
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
