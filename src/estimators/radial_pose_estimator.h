// Robust 1D radial absolute pose of one image (paper §3.2): LO-RANSAC over
// the 5-point radial solver with MSAC scoring on the radial reprojection
// error and the half-line test, then a robust (Cauchy) refinement.
//
// Image points are relative to the principal point (the distortion center),
// in pixels; the estimated cam_from_world has translation.z() == 0 because
// the forward translation is unobservable by a radial camera.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {

// Minimal estimator in the concept of COLMAP's RANSAC (like
// colmap/estimators/absolute_pose.h).
class RadialPoseEstimator {
 public:
  // Image point relative to the principal point, pixels.
  typedef Eigen::Vector2d X_t;
  // World point.
  typedef Eigen::Vector3d Y_t;
  // cam_from_world with translation.z() == 0.
  typedef Rigid3d M_t;

  static constexpr int kMinNumSamples = 5;

  // Up to 4 poses from 5 correspondences (SolveRadialPose5).
  static std::vector<M_t> Estimate(const std::vector<X_t>& points2D,
                                   const std::vector<Y_t>& points3D);

  // Squared radial reprojection errors; std::numeric_limits<double>::max()
  // for points on the wrong half-line or on the optical axis.
  static void Residuals(const std::vector<X_t>& points2D,
                        const std::vector<Y_t>& points3D, const M_t& model,
                        std::vector<double>* residuals);
};

// Non-minimal estimator for LO-RANSAC's local optimization, on all given
// points (the current inliers):
//  1. linear least squares on the homogeneous system
//     u (r2.X + t2) - v (r1.X + t1) = 0 in p = (r1, t1, r2, t2) (X centered
//     and scaled to unit RMS radius; x in pixels, so the algebraic error of
//     a point is its radial error times |(r1.X + t1, r2.X + t2)|): the
//     smallest eigenvector of A^T A, projected onto orthonormal [r1; r2]
//     (polar decomposition);
//  2. because a (near-)planar scene adds two null directions to that system
//     (r_i += lambda n, t_i -= lambda d for the plane n.X = d), also the
//     solutions of the rotation constraints in the span of the 3 smallest
//     eigenvectors (RadialPosesInSubspace), which are exact for planes;
//  3. each candidate gets the sign that puts most points on their half-line;
//     the one with the lowest robust cost is refined by Levenberg-Marquardt
//     over (rotation, tx, ty) on the radial error with a Cauchy loss of
//     scale loss_scale_px.
// Returns at most one pose.
class RadialPoseLocalEstimator {
 public:
  typedef Eigen::Vector2d X_t;
  typedef Eigen::Vector3d Y_t;
  typedef Rigid3d M_t;

  static constexpr int kMinNumSamples = 6;

  // Cauchy scale of the refinement, pixels. EstimateRadialPose sets it to
  // the inlier threshold, so that inliers keep weights in [0.5, 1].
  double loss_scale_px = 8.0;
  int max_num_iterations = 15;
  // Relative cost decrease at which the refinement stops. The local model
  // only has to sort points around the inlier threshold (a 1e-6 relative
  // change moves an inlier's error by ~1e-3 px); RefineRadialPose polishes
  // the final estimate to 1e-14. At 1e-14 here nearly every local
  // refinement ran all 15 iterations (the Cauchy loss' IRLS converges
  // linearly at residuals near s).
  double function_tolerance = 1e-6;

  std::vector<M_t> Estimate(const std::vector<X_t>& points2D,
                            const std::vector<Y_t>& points3D);

  static void Residuals(const std::vector<X_t>& points2D,
                        const std::vector<Y_t>& points3D, const M_t& model,
                        std::vector<double>* residuals) {
    RadialPoseEstimator::Residuals(points2D, points3D, model, residuals);
  }

 private:
  // Scratch buffer reused across calls: LO-RANSAC calls Estimate many times.
  std::vector<Eigen::Vector3d> points3D_normalized_;
};

struct RadialPoseEstimationOptions {
  double max_error_px = 8.0;  // inlier threshold on the radial error, pixels
  double confidence = 0.9999;
  int min_num_trials = 30;
  int max_num_trials = 10000;
  double min_inlier_ratio = 0.1;
  // Trials = multiplier * log(1 - confidence) / log(1 - w^5), w the best
  // model's inlier ratio so far. COLMAP's default multiplier, 3, is a margin
  // for a w estimated from an unrefined sample's inliers; here w comes from
  // the locally optimized model, whose inlier set is the full one (within
  // 1 % at 30 % outliers), so 1 is the bound the confidence states (0.9999:
  // 50 trials at w = 0.7 instead of 150).
  double dyn_num_trials_multiplier = 1.0;
  int min_num_inliers = 12;    // fewer: estimation fails
  double loss_scale_px = 1.0;  // Cauchy scale of the final refinement
  bool refine = true;          // final robust refinement on the inliers
};

struct RadialPoseEstimate {
  Rigid3d cam_from_world;  // translation.z() == 0
  std::vector<char> inlier_mask;
  int num_inliers = 0;
  int num_trials = 0;
  double radial_rms_px = 0;  // over inliers
};

// LORANSAC<RadialPoseEstimator, RadialPoseLocalEstimator,
// MEstimatorSupportMeasurer> (MSAC scoring; the adaptive trial count uses
// kMinNumSamples = 5), then RefineRadialPose on the inliers, after which the
// inliers are re-selected with the refined pose (radial error <=
// max_error_px on the correct half-line). Returns false, with *estimate
// unspecified, if the inputs differ in size, have fewer than
// max(5, min_num_inliers) points, or fewer than min_num_inliers inliers are
// found. Non-finite correspondences are treated as outliers. Uses COLMAP's
// thread-local random generator (colmap::SetPRNGSeed makes it repeatable).
bool EstimateRadialPose(const RadialPoseEstimationOptions& options,
                        const std::vector<Eigen::Vector2d>& points2D_centered,
                        const std::vector<Eigen::Vector3d>& points3D,
                        RadialPoseEstimate* estimate);

// Refinement of (rotation, tx, ty) on the inliers, minimizing
// sum_i s^2 log(1 + |e_i|^2 / s^2) over the radial reprojection errors e_i
// (Cauchy loss, s = loss_scale_px). It minimizes the same cost as a Ceres
// problem of RadialReprojectionCost blocks with ceres::CauchyLoss, by a
// dedicated Levenberg-Marquardt on the 5 unknowns (rotation update
// R <- exp([w]x) R) with analytic derivatives, which is ~10x faster than
// Ceres here (no per-residual setup). tz (0 for a radial pose) keeps its
// input value, as it does not affect the error. Non-finite correspondences
// are skipped. Returns false and leaves *cam_from_world unchanged if fewer
// than 5 inliers remain, the sizes differ, or the result is not finite.
bool RefineRadialPose(const RadialPoseEstimationOptions& options,
                      const std::vector<Eigen::Vector2d>& points2D_centered,
                      const std::vector<Eigen::Vector3d>& points3D,
                      const std::vector<char>& inlier_mask,
                      Rigid3d* cam_from_world);

}  // namespace rig_calibrator
