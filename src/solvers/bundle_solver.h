// The solver of the bundle adjustments (radial_bundle_adjuster.h,
// final_bundle_adjuster.h), one interface with two backends, as COLMAP has
// for its bundle adjuster:
//   kOwn    the project's Levenberg-Marquardt (bundle_levenberg_marquardt.h),
//           the default: written for this problem's structure, one symbolic
//           factorization for a sequence of solves, a result that does not
//           depend on the thread count;
//   kCeres  Ceres' (ceres_bundle_solver.h): the reference, to show that the
//           own solver reaches the same minimum
//           (tests/src/calibration/bundle_solver_backends_test.cc,
//           docs/solver_comparison.md).
// The own solver also gives the Gauss-Newton reduced system at the current
// values (BundleLevenbergMarquardt::LinearizeGaussNewton), which the
// calibration's covariance (calibration_uncertainty.h) marginalizes; it
// builds it with the own solver whatever backend ran the adjustment, as
// Ceres' has no such interface.
//
// Problem, for either. Residual blocks of 2 rows r_t(x), each a
// ceres::CostFunction over up to three camera-side parameter blocks (a pose,
// a cam_from_rig, intrinsics) and at most one point (3 values), with a robust
// loss rho:
//
//   min_x  F(x) = 1/2 sum_t rho(|r_t(x)|^2),
//
// parameter blocks on manifolds (steps in their tangent spaces,
// x' = Plus(x, delta)), the points eliminated by the Schur complement.
// Levenberg-Marquardt from the current values, stopping when a step changes
// F by at most function_tolerance * F, when |delta| <= parameter_tolerance *
// (|x| + parameter_tolerance), when max |gradient| <= gradient_tolerance, or
// after max_num_iterations steps (accepted or not). The own solver follows
// Ceres' Levenberg-Marquardt step for step (the same damping, trust-region
// updates and robust-loss correction); they part at the end: Ceres discards
// the step that meets the function tolerance, the own solver keeps it
// (docs/solver_comparison.md).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include <memory>
#include <string>
#include <vector>

namespace rig_calibrator {

struct BundleSolverOptions {
  int max_num_iterations = 100;
  double function_tolerance = 1e-6;
  double parameter_tolerance = 1e-8;
  double gradient_tolerance = 1e-10;
  double initial_trust_region_radius = 1e4;
  int num_threads = -1;  // -1: all cores; the own solver's result does not
                         // depend on it
  // One line per iteration on stdout (Ceres' columns; the own solver prints
  // |gradient| as nan on the line of an accepted step that ends the solve:
  // not evaluated there).
  bool print_progress = false;
};

struct BundleSolverSummary {
  enum class Termination { kConvergence, kNoConvergence, kFailure };
  Termination termination = Termination::kFailure;
  std::string message;
  int num_successful_steps = 0, num_unsuccessful_steps = 0;
  double initial_cost = 0, final_cost = 0;  // F
  int num_residual_blocks = 0, num_points = 0, reduced_system_size = 0;
  // Wall time of Solve, of which building the structure (batches, the
  // reduced system's pattern and its symbolic factorization; Ceres: the
  // problem and its preprocessing), evaluating residuals and Jacobians,
  // forming the reduced system and factorizing it (Ceres: both in
  // factorization_seconds, its linear solver's time) (seconds).
  double seconds = 0, structure_seconds = 0, evaluation_seconds = 0,
         schur_seconds = 0, factorization_seconds = 0;

  bool IsSolutionUsable() const { return termination != Termination::kFailure; }
  // One line: iterations, costs, termination (CONVERGENCE, NO_CONVERGENCE or
  // FAILURE) and the message.
  std::string BriefReport() const;
};

class BundleSolver {
 public:
  virtual ~BundleSolver() = default;

  // A camera-side parameter block of `size` values at `values`, refined on
  // `manifold` (null: Euclidean) as part of group `group` (>= 0; groups are
  // numbered from 0 without gaps, and a group's blocks are its columns in the
  // order they are added: one block row of the own solver's reduced system).
  // Not owned; they outlive Solve.
  virtual void AddParameterBlock(double* values, int size,
                                 const ceres::Manifold* manifold,
                                 int group) = 0;
  // Room for this many residual blocks and points (saves regrowing the
  // lists at 10^6 residuals).
  virtual void Reserve(size_t num_residual_blocks, size_t num_points) = 0;
  // A point (3 values, Euclidean), eliminated in the reduced system.
  virtual void AddPoint(double* values) = 0;
  // A residual block of 2 rows: `cost` over `parameters` (the pointers its
  // Evaluate takes, in its order; the parameter blocks added before). A
  // pointer that was added as a parameter block or a point is refined, any
  // other is held constant. `loss` null: least squares. Neither is owned.
  // Returns its index, from 0 in the order of addition.
  virtual size_t AddResidualBlock(const ceres::CostFunction* cost,
                                  const ceres::LossFunction* loss,
                                  const std::vector<double*>& parameters) = 0;

  // Changes between solves, for solves over a shrinking problem (e.g. after
  // outlier pruning): an inactive residual block counts as removed; a held
  // point (added by AddPoint) is a constant of its residuals, as if it had
  // not been added; the function tolerance of the next solves.
  virtual void SetResidualBlockActive(size_t index, bool active) = 0;
  virtual void SetPointHeld(const double* values, bool held) = 0;
  virtual void SetFunctionTolerance(double tolerance) = 0;

  // Minimizes F from the current values, which it updates (the last accepted
  // estimate; after a failure the values are the backend's last accepted
  // ones or the initial ones, and are not to be used).
  virtual void Solve(BundleSolverSummary* summary) = 0;
};

enum class BundleSolverBackend { kOwn, kCeres };

// Parses/prints "own", "ceres".
bool BundleSolverBackendFromName(const std::string& name,
                                 BundleSolverBackend* backend);
std::string BundleSolverBackendName(BundleSolverBackend backend);

std::unique_ptr<BundleSolver> MakeBundleSolver(
    BundleSolverBackend backend,
    const BundleSolverOptions& options);

}  // namespace rig_calibrator
