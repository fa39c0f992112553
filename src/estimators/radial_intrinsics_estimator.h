// The camera upgrade's solvers (paper §3.5) in COLMAP's estimator concept
// (<colmap/optim/ransac.h>), for its LORANSAC: the minimal solver draws the
// hypotheses, the least-squares solver is the local optimization on their
// inliers. Notation: src/solvers/radial_intrinsics.h.
#pragma once

// Before any std::vector<Eigen::Vector2d> is instantiated: COLMAP
// specializes std::vector for fixed-size Eigen types.
#include <colmap/optim/ransac.h>

#include <Eigen/Core>
#include <optional>
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

// What both estimators share: the types, the profile, the known focal
// length and the residuals. kKnownFocal: the hypotheses have the focal
// length `known_focal` (the user holds it), so the minimal sample is one
// correspondence smaller.
template <int kNumRadialTerms, bool kKnownFocal>
class RadialIntrinsicsEstimatorBase {
 public:
  typedef Eigen::Vector2d X_t;  // pixel relative to the principal point
  typedef Eigen::Vector3d Y_t;  // camera-frame point without tz
  typedef RadialIntrinsics M_t;

  static_assert(kNumRadialTerms >= 0 && kNumRadialTerms <= 2,
                "0 to 2 radial terms");

  RadialProfile profile = RadialProfile::kPolynomial;
  double known_focal = 0;  // in pixels, > 0; used only if kKnownFocal

  void Residuals(const std::vector<X_t>& x, const std::vector<Y_t>& points_cam,
                 const M_t& model, std::vector<double>* residuals) const {
    RadialIntrinsicsResiduals(x, points_cam, model, residuals);
  }

 protected:
  std::optional<double> KnownFocal() const {
    return kKnownFocal ? std::optional<double>(known_focal) : std::nullopt;
  }
};

// Minimal estimator: SolveMinimalRadialIntrinsics on kNumRadialTerms + 2
// correspondences (f, the radial terms and tz), kNumRadialTerms + 1 with a
// known focal length (the radial terms and tz).
template <int kNumRadialTerms, bool kKnownFocal = false>
class RadialIntrinsicsEstimator
    : public RadialIntrinsicsEstimatorBase<kNumRadialTerms, kKnownFocal> {
 public:
  using Base = RadialIntrinsicsEstimatorBase<kNumRadialTerms, kKnownFocal>;
  static constexpr int kMinNumSamples = kNumRadialTerms + (kKnownFocal ? 1 : 2);

  std::vector<RadialIntrinsics> Estimate(
      const std::vector<Eigen::Vector2d>& x,
      const std::vector<Eigen::Vector3d>& points_cam) const {
    return SolveMinimalRadialIntrinsics(x, points_cam, Base::profile,
                                        kNumRadialTerms, Base::KnownFocal());
  }
};

// Local (non-minimal) estimator: SolveRadialIntrinsicsLeastSquares on all
// given correspondences (the current inliers), at least one more than the
// minimal sample.
template <int kNumRadialTerms, bool kKnownFocal = false>
class RadialIntrinsicsLocalEstimator
    : public RadialIntrinsicsEstimatorBase<kNumRadialTerms, kKnownFocal> {
 public:
  using Base = RadialIntrinsicsEstimatorBase<kNumRadialTerms, kKnownFocal>;
  static constexpr int kMinNumSamples =
      RadialIntrinsicsEstimator<kNumRadialTerms, kKnownFocal>::kMinNumSamples +
      1;

  // The local optimization runs on at most this many of the inliers, evenly
  // strided: it is called for every better hypothesis, up to ten times each
  // (COLMAP's LORANSAC), and its grid search over tz costs a profile fit per
  // grid point, while the few parameters it estimates are as well determined
  // by 1 500 rows as by 10^4 (the upgrade's least squares then fits all).
  static constexpr size_t kMaxNumRows = 1500;

  std::vector<RadialIntrinsics> Estimate(
      const std::vector<Eigen::Vector2d>& x,
      const std::vector<Eigen::Vector3d>& points_cam) const {
    if (x.size() <= kMaxNumRows) {
      return SolveRadialIntrinsicsLeastSquares(
          x, points_cam, Base::profile, kNumRadialTerms, Base::KnownFocal());
    }
    std::vector<Eigen::Vector2d> x_rows;
    std::vector<Eigen::Vector3d> points_rows;
    x_rows.reserve(kMaxNumRows);
    points_rows.reserve(kMaxNumRows);
    for (size_t k = 0; k < kMaxNumRows; ++k) {
      const size_t row = k * x.size() / kMaxNumRows;
      x_rows.push_back(x[row]);
      points_rows.push_back(points_cam[row]);
    }
    return SolveRadialIntrinsicsLeastSquares(x_rows, points_rows,
                                             Base::profile, kNumRadialTerms,
                                             Base::KnownFocal());
  }
};

// The upgrade's initialization (paper §3.5): COLMAP's LORANSAC with the two
// estimators above for `num_radial_terms` (0..2), inlier-count support and
// SeededRandomSampler, so that the result depends only on the input. With
// `known_focal` (> 0) every hypothesis and the result have that focal length
// exactly. False if no model is found.
bool EstimateRadialIntrinsicsRansac(
    const colmap::RANSACOptions& options, RadialProfile profile,
    int num_radial_terms, const std::optional<double>& known_focal,
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, RadialIntrinsics* model);

}  // namespace rig_calibrator
