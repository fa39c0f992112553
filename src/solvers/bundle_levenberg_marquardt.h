// Levenberg-Marquardt for bundle-adjustment problems: the own backend of the
// bundle solver (bundle_solver.h; the default of the radial and the final
// bundle adjustment, with Ceres' as the other backend), written for their
// fixed structure instead of Ceres' general one.
//
// Problem. Residual blocks of 2 rows, r_t(x), each a ceres::CostFunction
// (analytic Jacobians: rig_reprojection_cost.h) over up to three "camera
// side" parameter blocks (a pose, a cam_from_rig, intrinsics) and at most one
// point (3 values), with a robust loss rho:
//
//   min_x  F(x) = 1/2 sum_t rho(|r_t(x)|^2).
//
// Parameter blocks live on manifolds (ceres::Manifold: quaternion x R^3 for
// poses, a subset manifold for partly held intrinsics); steps are taken in
// their tangent spaces, x' = Plus(x, delta). The tangent Jacobian of a block
// is the cost's ambient one times the manifold's PlusJacobian, or comes from
// the cost directly (TangentJacobianCost). Camera-side blocks are put in
// groups (e.g. a camera's cam_from_rig and intrinsics): a group is one block
// row of the reduced system, so that an observation touches two of them
// instead of three.
//
// Step. As Ceres' Levenberg-Marquardt: with the robust loss folded into r and
// J by Triggs' correction (ceres/corrector.h's rule: sqrt(rho') scaling, plus
// the curvature term when rho'' > 0), the step solves
//
//   (J^T J + D / mu) delta = -J^T r,   D = clamp(diag(J^T J), 1e-6, 1e32),
//
// mu the trust-region radius. The points are eliminated by their 3 x 3 blocks
// (Schur complement): with U, V_p, W_p the camera-side, point and mixed
// blocks of J^T J + D / mu, and b_c, b_p those of J^T r,
//
//   (U - sum_p W_p^T V_p^-1 W_p) delta_c = -b_c + sum_p W_p^T V_p^-1 b_p,
//   delta_p = V_p^-1 (-b_p - W_p delta_c),
//
// the reduced system (groups) is factorized by CHOLMOD's supernodal sparse
// Cholesky (symbolic analysis once per Solve). A step is accepted when the
// cost decrease is at least 1e-3 of the model's, rho = (F(x) - F(x')) /
// (1/2 |r|^2 - 1/2 |r + J delta|^2); then mu /= max(1/3, 1 - (2 rho - 1)^3),
// else mu is divided by a factor that doubles with every rejection in a row.
// Stops when a step changes F by less than function_tolerance * F (an
// accepted one is kept, without linearizing there), when the
// step is below parameter_tolerance * (|x| + parameter_tolerance), when the
// gradient's largest entry is below gradient_tolerance, or after
// max_num_iterations steps (accepted or not).
//
// Threads, deterministically. The residual blocks and the points are cut into
// a fixed number of chunks, whatever the thread count; each chunk evaluates
// into its own slots and adds its part of the reduced system, the costs and
// gradients into its own copy, and the copies are added in chunk order. The
// result is therefore bit-identical for any thread count, unlike Ceres 2.1,
// whose threads add in the order they finish.
#pragma once

#include <memory>
#include <vector>

#include "src/geometry/tangent_jacobian_cost.h"
#include "src/solvers/bundle_solver.h"

namespace rig_calibrator {

// The kOwn backend of bundle_solver.h (its contract there; what follows is
// this backend's).
class BundleLevenbergMarquardt final : public BundleSolver {
 public:
  explicit BundleLevenbergMarquardt(
      const BundleSolverOptions& options);
  ~BundleLevenbergMarquardt() override;

  void AddParameterBlock(double* values, int size,
                         const ceres::Manifold* manifold, int group) override;
  void Reserve(size_t num_residual_blocks, size_t num_points) override;
  void AddPoint(double* values) override;
  // A TangentJacobianCost is evaluated by EvaluateTangent where it can be.
  size_t AddResidualBlock(const ceres::CostFunction* cost,
                          const ceres::LossFunction* loss,
                          const std::vector<double*>& parameters) override;

  // These keep the structure (the reduced system's pattern and its symbolic
  // factorization, built at the first Solve after an addition): an inactive
  // residual block has a zero residual and Jacobian.
  void SetResidualBlockActive(size_t index, bool active) override;
  void SetPointHeld(const double* values, bool held) override;
  void SetFunctionTolerance(double tolerance) override;

  // After a failure midway, the values are the last accepted estimate.
  void Solve(BundleSolverSummary* summary) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rig_calibrator
