// The prior of a frameset's estimated translational velocity v (the time
// model of the final bundle adjustment, final_bundle_adjuster.h;
// frameset_motion.h): v near the polynomial's p1 through the frameset
// poses,
//
//   r = ((v_a - p1_a) / sigma, (v_b - p1_b) / sigma)   (pixels),
//
// axes a = first_axis and b = a + 1 (first_axis 2: b is none and the second
// row is 0), so that a deviation of sigma costs what one pixel of
// reprojection error costs. sigma is FramesetVelocityPriorSigma: the
// polynomial's own error as the velocities' deviations from it estimate it.
// The images override the prior where they see the motion (different
// cameras' offsets, rolling-shutter rows); it holds what they do not see:
// a frameset seen at one instant, and the velocity error common to all
// framesets, which moves every camera by delta_c times it exactly as a
// change of its cam_from_rig centre would (with sigma at the RMS speed
// instead, the synthetic ring at 5 Hz with offsets kept 2.3 mm of centre
// error; with the estimated sigma 0.56 mm). p1 and sigma are read by
// pointer at every evaluation: the adjustment recomputes them between
// solves.
#pragma once

#include <ceres/sized_cost_function.h>

#include "src/geometry/frameset_motion.h"

namespace rig_calibrator {

class FramesetVelocityPriorCost final
    : public ceres::SizedCostFunction<2, 3> {
 public:
  FramesetVelocityPriorCost(const FramesetMotion* motion, const double* sigma,
                            int first_axis)
      : motion_(motion), sigma_(sigma), first_axis_(first_axis) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double weight = 1 / *sigma_;
    for (int row = 0; row < 2; ++row) {
      const int axis = first_axis_ + row;
      residuals[row] =
          axis < 3 ? weight * (parameters[0][axis] - (*motion_)[9 + axis]) : 0;
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        for (int k = 0; k < 3; ++k) {
          jacobians[0][3 * row + k] = k == axis ? weight : 0;
        }
      }
    }
    return true;
  }

 private:
  const FramesetMotion* motion_;
  const double* sigma_;
  const int first_axis_;
};

}  // namespace rig_calibrator
