// The prior of a frameset's estimated translational velocity and
// acceleration e = [v, a] (the time model of the final bundle adjustment,
// final_bundle_adjuster.h; frameset_motion.h): e near the polynomial's
// [p1, p2] through the frameset poses,
//
//   r = (W_k (e - [p1, p2]), W_(k+1) (e - [p1, p2]))   (pixels),
//
// W_k row k of the whitening W (TranslationPriorWhitening: the inverse
// square root of the covariance of the polynomial's own error as the
// estimates' deviations from it estimate it), rows k = first_row and
// k + 1 (three costs, first_row 0, 2, 4, make the whole prior), so that a
// deviation of one standard deviation in any direction costs what one
// pixel of reprojection error costs. The images override the prior where
// they see the motion (different cameras' offsets, rolling-shutter rows);
// it holds what they do not see: a frameset seen at one instant, and the
// velocity error common to all framesets, which moves every camera by
// delta_c times it exactly as a change of its cam_from_rig centre would
// (with the RMS speed as the deviation instead, the synthetic ring at 5 Hz
// with offsets kept 2.3 mm of centre error; with the estimated one
// 0.56 mm). p1, p2 and W are read by pointer at every evaluation: the
// adjustment recomputes them between solves.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "src/geometry/frameset_motion.h"

namespace rig_calibrator {

class TranslationPriorCost final
    : public ceres::SizedCostFunction<2, 6> {
 public:
  TranslationPriorCost(const FramesetMotion* motion,
                            const Eigen::Matrix<double, 6, 6>* whitening,
                            int first_row)
      : motion_(motion), whitening_(whitening), first_row_(first_row) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const TranslationDerivatives> estimate(parameters[0]);
    const Eigen::Map<const TranslationDerivatives> polynomial(
        &(*motion_)[9]);
    for (int row = 0; row < 2; ++row) {
      residuals[row] =
          whitening_->row(first_row_ + row).dot(estimate - polynomial);
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        for (int k = 0; k < 6; ++k) {
          jacobians[0][6 * row + k] = (*whitening_)(first_row_ + row, k);
        }
      }
    }
    return true;
  }

 private:
  const FramesetMotion* motion_;
  const Eigen::Matrix<double, 6, 6>* whitening_;
  const int first_row_;
};

}  // namespace rig_calibrator
