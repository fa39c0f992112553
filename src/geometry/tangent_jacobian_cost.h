// The cost-function interface for Jacobians in a manifold's tangent space,
// which the bundle adjustments' solver (bundle_levenberg_marquardt.h) uses
// instead of multiplying ambient Jacobians by PlusJacobians.
#pragma once

#include <ceres/cost_function.h>

namespace rig_calibrator {

// A cost that also gives its Jacobians in the tangent spaces of the
// manifolds it was written for: in EvaluateTangent, jacobians[k] of a block
// with TangentSize(k) > 0 is the 2 x TangentSize(k) row-major
//   d r(Plus_k(x_k, delta)) / d delta  at delta = 0,
// Plus_k that manifold's (the cost's documentation names it); the other
// blocks' are ambient, as in Evaluate. The solver uses it for a residual
// block whose such blocks are constant or refined on a manifold of that
// tangent size (which must be the cost's), and then skips, per residual and
// linearization, the products of the ambient Jacobians with the manifolds'
// PlusJacobians (2 x 7 by 7 x 6 for a pose); otherwise it calls Evaluate.
class TangentJacobianCost : public ceres::CostFunction {
 public:
  virtual int TangentSize(int parameter_block) const = 0;
  virtual bool EvaluateTangent(double const* const* parameters,
                               double* residuals, double** jacobians) const = 0;
};

// A rig cost whose blocks 0 and 1 are poses (rig_from_world,
// cam_from_rig) on RigPoseManifold (tangent size 6), the others ambient:
// Evaluate and EvaluateTangent are Derived's one
//   template <bool kTangent> bool EvaluateImpl(parameters, residuals,
//                                              jacobians) const
// (rig_reprojection_cost.h, timed_rig_reprojection_cost.h).
template <typename Derived>
class RigPosesTangentCost : public TangentJacobianCost {
 public:
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return static_cast<const Derived*>(this)->template EvaluateImpl<false>(
        parameters, residuals, jacobians);
  }
  int TangentSize(int parameter_block) const override {
    return parameter_block < 2 ? 6 : 0;
  }
  bool EvaluateTangent(double const* const* parameters, double* residuals,
                       double** jacobians) const override {
    return static_cast<const Derived*>(this)->template EvaluateImpl<true>(
        parameters, residuals, jacobians);
  }
};

}  // namespace rig_calibrator
