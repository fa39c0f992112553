// The camera upgrade's solvers (paper §3.5) in COLMAP's estimator concept
// (<colmap/optim/ransac.h>), for its LORANSAC: the minimal solver draws the
// hypotheses, the least-squares solver is the local optimization on their
// inliers. Notation: src/solvers/radial_intrinsics.h.
#pragma once

// Before any std::vector<Eigen::Vector2d> is instantiated: COLMAP
// specializes std::vector for fixed-size Eigen types.
#include <colmap/optim/ransac.h>

#include <Eigen/Core>
#include <vector>

#include "src/solvers/minimal_radial_intrinsics_solver.h"
#include "src/solvers/radial_intrinsics.h"
#include "src/solvers/radial_intrinsics_least_squares.h"

namespace rig_calibrator {

// Squared full reprojection errors of `model` in pixels^2;
// std::numeric_limits<double>::max() for c + tz <= 0 (a point the model
// cannot project).
void RadialIntrinsicsResiduals(const std::vector<Eigen::Vector2d>& x,
                               const std::vector<Eigen::Vector3d>& points_cam,
                               const RadialIntrinsics& model,
                               std::vector<double>* residuals);

// What both estimators share: the types, the profile and the residuals.
template <int kNumRadialTerms>
class RadialIntrinsicsEstimatorBase {
 public:
  typedef Eigen::Vector2d X_t;  // pixel relative to the principal point
  typedef Eigen::Vector3d Y_t;  // camera-frame point without tz
  typedef RadialIntrinsics M_t;

  static_assert(kNumRadialTerms >= 0 && kNumRadialTerms <= 2,
                "0 to 2 radial terms");

  RadialProfile profile = RadialProfile::kPolynomial;

  void Residuals(const std::vector<X_t>& x, const std::vector<Y_t>& points_cam,
                 const M_t& model, std::vector<double>* residuals) const {
    RadialIntrinsicsResiduals(x, points_cam, model, residuals);
  }
};

// Minimal estimator: SolveMinimalRadialIntrinsics on kNumRadialTerms + 2
// correspondences (f, the radial terms and tz).
template <int kNumRadialTerms>
class RadialIntrinsicsEstimator
    : public RadialIntrinsicsEstimatorBase<kNumRadialTerms> {
 public:
  using Base = RadialIntrinsicsEstimatorBase<kNumRadialTerms>;
  static constexpr int kMinNumSamples = kNumRadialTerms + 2;

  std::vector<RadialIntrinsics> Estimate(
      const std::vector<Eigen::Vector2d>& x,
      const std::vector<Eigen::Vector3d>& points_cam) const {
    return SolveMinimalRadialIntrinsics(x, points_cam, Base::profile,
                                        kNumRadialTerms);
  }
};

// Local (non-minimal) estimator: SolveRadialIntrinsicsLeastSquares on all
// given correspondences (the current inliers), at least one more than the
// minimal sample.
template <int kNumRadialTerms>
class RadialIntrinsicsLocalEstimator
    : public RadialIntrinsicsEstimatorBase<kNumRadialTerms> {
 public:
  using Base = RadialIntrinsicsEstimatorBase<kNumRadialTerms>;
  static constexpr int kMinNumSamples = kNumRadialTerms + 3;

  std::vector<RadialIntrinsics> Estimate(
      const std::vector<Eigen::Vector2d>& x,
      const std::vector<Eigen::Vector3d>& points_cam) const {
    return SolveRadialIntrinsicsLeastSquares(x, points_cam, Base::profile,
                                             kNumRadialTerms);
  }
};

// The upgrade's initialization (paper §3.5): COLMAP's LORANSAC with the two
// estimators above for `num_radial_terms` (0..2), inlier-count support and
// SeededRandomSampler, so that the result depends only on the input. False if
// no model is found.
bool EstimateRadialIntrinsicsRansac(
    const colmap::RANSACOptions& options, RadialProfile profile,
    int num_radial_terms, const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, RadialIntrinsics* model);

}  // namespace rig_calibrator
