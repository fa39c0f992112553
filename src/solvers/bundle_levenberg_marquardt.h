// Levenberg-Marquardt for bundle-adjustment problems: the own backend of the
// bundle solver (bundle_solver.h; the default of the radial and the final
// bundle adjustment, with Ceres' as the other backend), written for their
// fixed structure instead of Ceres' general one.
//
// Problem. Residual blocks of 2 rows, r_t(x), each a ceres::CostFunction
// (analytic Jacobians: rig_reprojection_cost.h; automatic ones for the time
// model's timed_rig_reprojection_cost.h) over up to five "camera side"
// parameter blocks (a pose, a cam_from_rig, intrinsics, and with the final
// adjustment's time model a capture-time offset and a line delay; its
// velocities' prior, translation_prior_cost.h, up to eight) and at most one
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
// Gauss-Newton system (LinearizeGaussNewton). The same evaluation and
// elimination, without the robust loss and without damping, is the reduced
// system that the calibration's covariance (calibration_uncertainty.h)
// marginalizes: one implementation of "the Jacobians at the current values,
// the points eliminated by their 3 x 3 blocks" for the step and the
// covariance. There V_p may be singular (a point seen once has no
// information along its ray), and V_p^+, its pseudo-inverse, takes the place
// of V~_p^-1.
//
// Threads, deterministically. The residual blocks and the points are cut into
// a fixed number of chunks, whatever the thread count; each chunk evaluates
// into its own slots and adds its part of the reduced system, the costs and
// gradients into its own copy, and the copies are added in chunk order. The
// result is therefore bit-identical for any thread count, unlike Ceres 2.1,
// whose threads add in the order they finish.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>
#include <string>
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

  // The Gauss-Newton reduced system at the current values (see the top of
  // the file): J the Jacobian of the residuals with rho(s) = s, in the
  // blocks' tangent spaces, U, V_p, W_p the camera-side, point and mixed
  // blocks of J^T J (no damping), and
  //
  //   S = U - sum_p W_p^T V_p^+ W_p,
  //
  // V_p^+ the pseudo-inverse of V_p (eigenvalues below 1e-12 of the largest
  // count as 0: a direction without information in V_p has none in W_p
  // either, so the elimination is exact). Built by the step's code, in its
  // chunks: bit-identical on any thread count. The Ceres backend has no
  // counterpart; the covariance builds it with this class whatever backend
  // ran the adjustment. False, with `error`, when the structure cannot be
  // built or a residual cannot be evaluated. The accessors below read its
  // result, valid until the next Solve or LinearizeGaussNewton.
  bool LinearizeGaussNewton(std::string* error);
  // The upper triangle of S; group g's tangent coordinates are its rows
  // [GroupOffset(g), GroupOffset(g) + its size), its blocks' in the order
  // they were added.
  const Eigen::SparseMatrix<double>& ReducedMatrix() const;
  int GroupOffset(int group) const;
  // sum_p rank V_p: the point coordinates the data determine.
  int64_t NumDeterminedPointParameters() const;
  // r_t of residual block `index` (AddResidualBlock's), without loss.
  Eigen::Vector2d Residual(size_t index) const;
  // g_c += weight J_c^T r_t over the camera side (S's coordinates); returns
  // weight J_p^T r_t over its point (zero without one).
  Eigen::Vector3d AddGradient(size_t index, double weight,
                              Eigen::VectorXd* camera_gradient) const;
  // For a refined point p (AddPoint's index) with a point-side vector b_p of
  // the full system [U W^T; W V] [x_c; x_p] = [b_c; b_p]: its elimination
  // into the camera side, b_c -= W_p^T V_p^+ b_p, and its back-substitution,
  // x_p = V_p^+ (b_p - W_p x_c).
  void EliminatePointVector(int point, const Eigen::Vector3d& b_p,
                            Eigen::VectorXd* b_c) const;
  Eigen::Vector3d BackSubstitutePoint(int point, const Eigen::Vector3d& b_p,
                                      const Eigen::VectorXd& x_c) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rig_calibrator
