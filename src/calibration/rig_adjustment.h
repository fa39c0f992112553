// The state of the final bundle adjustment (final_bundle_adjuster.h) between
// its solves: copies of the calibration being refined (written back only on
// success), the observations that take part, and the map points being
// refined. Internal to AdjustRig; split over
//   rig_adjustment.cc           state, evaluation, point selection, results,
//   rig_adjustment_outliers.cc  outlier pruning,
//   rig_adjustment_problem.cc   the problem and its solve,
//   rig_adjustment_time_model.cc  the time model's motion and results.
#pragma once

#include <ceres/ceres.h>

#include <array>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "src/calibration/final_bundle_adjuster.h"
#include "src/geometry/frameset_motion.h"
#include "src/rig/rig_dataset.h"
#include "src/solvers/bundle_solver.h"
#include "src/solvers/huge_page_allocator.h"

namespace rig_calibrator {

class RigAdjustment {
 public:
  // The observations are the inliers (inlier_mask) of the images of
  // calibrated cameras in framesets with a rig pose.
  RigAdjustment(const FinalBundleAdjustmentOptions& options,
                const RigDataset& dataset, const RigCalibration& calibration);

  size_t NumObservations() const { return observations_.size(); }
  // Map observations of refined points that the last solve used.
  size_t NumMapObservationsInProblem() const;
  size_t NumMapRejected() const { return num_map_rejected_; }
  // Given inliers removed since the construction.
  size_t NumRejected() const {
    return num_given_inliers_ - observations_.size();
  }
  // Whether the last solve held something observed fixed in the world: a
  // point (without id, or seen once) or a map image's pose. Either anchors
  // the world frame and scale.
  bool HasFixedPoints() const { return has_fixed_points_; }

  // RMS of |r| over the current rig observations at the current estimate.
  double RmsError() const;
  // The same over the map observations of the points being refined (those
  // selected by the last solve, or at the first call those it will select).
  double MapRmsError();

  // Removes observations behind their camera or farther than
  // max_depth_factor * the median depth; with `prune_residuals` also those
  // whose error exceeds their camera's threshold (see the options). Returns
  // how many were removed.
  size_t RejectOutliers(bool prune_residuals);
  // The map part of RejectOutliers(true) at the current estimate, without
  // solving again: after the last solve, so that the map observations kept
  // all fit their refined points (the rejected ones are dropped from the
  // output model). Returns how many were rejected.
  size_t RejectMapOutliers();

  // Builds the problem over the current observations and solves it, until
  // an iteration lowers the cost by less than function_tolerance of it.
  // False (logged) when the solver finds no usable solution.
  bool Solve(double function_tolerance,
             BundleSolverSummary* summary);

  // Writes the estimate and the per-image results (see AdjustRig).
  void WriteTo(RigCalibration* calibration) const;

  // With the options' time model: per dataset camera its current offset
  // and line delay, and whether each is estimated (their sigmas: the
  // calibration's uncertainty, calibration_uncertainty.h).
  std::vector<CameraCaptureTime> CaptureTimes() const;

 private:
  // One correspondence of one dataset image, with its cost and residual
  // block in the problem (made at the first solve).
  struct Observation {
    int image = -1;
    int correspondence = -1;
    std::unique_ptr<ceres::CostFunction> cost;
    size_t residual_index = 0;  // its residual block in solver_
    // Its point's slot in refined_points_ (SelectRefinedPoints), -1: the
    // point is held at its map position.
    int64_t refined_slot = -1;
  };
  // One observation of a map image (dataset.map_images).
  struct MapObservationRef {
    int image = -1;
    int observation = -1;
  };
  // Where a point is and its residual at the current estimate.
  struct ObservationError {
    double depth = 0;  // z in the camera frame
    Eigen::Vector2d residual = Eigen::Vector2d::Zero();
  };
  // Per observation (10^6), in huge pages (huge_page_allocator.h): the
  // error, and with it its pruning slot.
  using ObservationErrors = LargeVector<ObservationError>;
  using SlotErrors = LargeVector<std::pair<int, ObservationError>>;

  // With a time model: the frameset motions (frameset_motion.h) from the
  // current rig poses and the prior of the estimated velocities and
  // accelerations (EstimateTranslationPrior), before each solve; at the
  // first call the estimates start at the motions' p1 and p2 unless given.
  void UpdateFramesetMotions();
  // The priors (translation_prior_cost.h) of the framesets whose pose,
  // velocity and acceleration are refined, after the observations'
  // residuals: an innovation cost where the previous frameset is refined
  // too, else the frameset's own.
  void AddTranslationPriors(const std::vector<char>& frameset_refined);

  const Correspondence& CorrespondenceOf(const Observation& observation) const;
  int CameraOf(const Observation& observation) const;
  ObservationError Evaluate(const Observation& observation) const;
  // Evaluate of every rig observation, in their order, on all threads.
  ObservationErrors EvaluateObservations() const;
  ObservationError Evaluate(const MapObservationRef& observation) const;
  // (slot, Evaluate) of every rig observation (`with_rig_observations`),
  // then of `map_observations`, in that order, on all threads.
  SlotErrors EvaluateWithSlots(
      bool with_rig_observations,
      const std::vector<MapObservationRef>& map_observations) const;
  int NumThreads() const;
  const MapObservation& MapObservationOf(
      const MapObservationRef& observation) const;
  // Pruning thresholds are per rig camera, then per map camera.
  int MapCameraSlot(const MapObservationRef& observation) const;
  // The current map observations of refined points, and those that take
  // part in the problem (none without use_map_observations).
  std::vector<MapObservationRef> MapObservationsOfRefinedPoints() const;
  std::vector<MapObservationRef> MapObservationsInProblem() const;
  // The refined position of the observed point, else its map position.
  const Eigen::Vector3d& PointOf(const Observation& observation) const;
  const Eigen::Vector3d& PointOf(int64_t point3D_id) const;
  bool IsPointRefined(int64_t point3D_id) const;
  // The points to refine in the next solve: those with an id that have at
  // least two current observations (seen once, a point has 3 unknowns for 2
  // residuals), counting the map images' (use_map_observations) for points
  // the rig images see and, with refine_map, every map point. They keep
  // their refined position from an earlier solve, or start at their map
  // position.
  void SelectRefinedPoints();
  // SelectRefinedPoints once the problem is built; `refined_ids` the new
  // selection (sorted), `rig_ids` the rig observations' (point3D_id, index),
  // sorted.
  void HoldPointsNoLongerRefined(
      const std::vector<int64_t>& refined_ids,
      const std::vector<std::pair<int64_t, size_t>>& rig_ids);
  // The depths an observation may have (final_bundle_adjuster.h's pruning
  // rules): within max_depth_factor of the median depth of the rig
  // observations in `errors` (EvaluateWithSlots with them first), either
  // way; any positive depth without rig observations.
  struct DepthRange {
    double min = 0, max = std::numeric_limits<double>::infinity();
    bool Contains(double depth) const {
      return depth > 0 && depth >= min && depth <= max;
    }
  };
  DepthRange DepthRangeOf(const SlotErrors& errors) const;
  // Per slot (rig cameras, then map cameras), max(min_outlier_error_px,
  // outlier_sigma_factor * sigma), sigma the robust spread of the residual
  // components of the slot's observations in front of their camera.
  std::vector<double> MaxErrorPerSlot(const SlotErrors& errors) const;

  // The problem (solver_), at the first solve: its blocks and residuals over
  // the rig observations and `map_observations` (MapObservationsInProblem()).
  void AddParameterBlocks(
      const std::vector<MapObservationRef>& map_observations);
  void AddResidualBlocks(
      const std::vector<MapObservationRef>& map_observations);
  // At a later solve: the residual blocks of the observations that left
  // (pruned, or of map observations of points no longer refined) made
  // inactive, and has_fixed_points_.
  void UpdateResidualBlocks();

  const FinalBundleAdjustmentOptions& options_;
  const RigDataset& dataset_;
  std::vector<colmap::Camera> cameras_;
  std::vector<PoseParams> cam_from_rig_;
  std::vector<PoseParams> rig_from_world_;
  std::vector<bool> has_rig_pose_;
  // The time model (empty without): per camera its offset and line delay,
  // per frameset its motion from the poses and its velocity's and
  // acceleration's weights on them (sized once: the costs point into
  // them), whether that motion leaves the frameset's own pose out, and
  // its estimated translational velocity and acceleration, which replace
  // the motion's p1 and p2 (frameset_motion.h); their prior's whitening and
  // costs.
  std::vector<double> time_offsets_;
  std::vector<double> line_delays_;
  std::vector<FramesetMotion> frameset_motions_;
  std::vector<TranslationStencil> translation_stencils_;
  std::vector<char> frameset_without_own_pose_;
  std::vector<TranslationDerivatives> frameset_translations_;
  bool translations_started_ = false;
  TranslationPrior translation_prior_;
  std::vector<std::unique_ptr<ceres::CostFunction>> translation_prior_costs_;
  LargeVector<Observation> observations_;
  size_t num_given_inliers_ = 0;
  // The map images (empty unless refine_points and map images):
  // intrinsics, poses, per observation whether it was rejected.
  std::vector<colmap::Camera> map_cameras_;
  std::vector<PoseParams> map_cam_from_world_;
  std::vector<std::vector<char>> map_rejected_;
  size_t num_map_rejected_ = 0;
  bool points_selected_ = false;
  // No observation has left since the last SelectRefinedPoints, so that
  // selection still holds.
  bool selection_current_ = false;
  // cam_from_rig of a map image seen as a one-camera rig (the identity,
  // constant), so that its residuals are RigReprojectionCosts too.
  PoseParams identity_pose_ = {1, 0, 0, 0, 0, 0, 0};
  // By point3D_id: the map positions. The points being refined are one
  // vector in increasing point3D_id order (refined_point_index_: id -> slot),
  // the order in which the solver is given them.
  std::unordered_map<int64_t, Eigen::Vector3d> map_points_;
  std::vector<Eigen::Vector3d> refined_points_;
  std::unordered_map<int64_t, size_t> refined_point_index_;
  // The refined point of point3D_id, or null.
  Eigen::Vector3d* RefinedPoint(int64_t point3D_id);
  const Eigen::Vector3d* RefinedPoint(int64_t point3D_id) const;
  bool has_fixed_points_ = false;
  // The solver does not own these; they outlive every solve.
  std::unique_ptr<ceres::LossFunction> loss_;
  std::unique_ptr<ceres::Manifold> pose_manifold_;
  std::vector<std::unique_ptr<ceres::Manifold>> intrinsics_manifolds_;
  std::vector<std::unique_ptr<ceres::CostFunction>> map_costs_;
  // The map observations in the problem and their residual blocks, which
  // follow the num_rig_residuals_ of the rig observations.
  std::vector<std::pair<MapObservationRef, size_t>> map_residuals_;
  size_t num_rig_residuals_ = 0;
  // One problem for all solves, built at the first (its structure and
  // symbolic factorization with it: 0.5 s per solve and 0.7 s per build at
  // 500 framesets x 10 cameras); later solves deactivate the observations
  // that left and hold the points no longer refined. Last: destroyed first,
  // it points into the members above.
  std::unique_ptr<BundleSolver> solver_;
};

}  // namespace rig_calibrator
