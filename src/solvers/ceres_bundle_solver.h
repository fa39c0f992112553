// The kCeres backend of bundle_solver.h: the same problem solved by Ceres'
// Levenberg-Marquardt, as the reference that the own solver
// (bundle_levenberg_marquardt.h) is compared with.
//
// Each Solve builds a ceres::Problem from what was added: the active residual
// blocks with their costs and losses; the parameter blocks on their
// manifolds; the points that are not held in elimination group 0 of
// SPARSE_SCHUR (with no free point, Ceres picks the eliminated blocks
// itself); every other pointer of a residual block constant. Inactive
// residual blocks are simply not in it, held points are constant: the
// problem is the one the own solver solves, not an approximation of it.
// Rebuilding costs little next to a solve, and keeps Ceres' state from one
// solve out of the next. The groups of AddParameterBlock (the own solver's
// block rows) do not apply: Ceres reduces per block. Solver options:
// LEVENBERG_MARQUARDT with the given tolerances, max_num_iterations, initial
// trust region radius and threads (-1: all cores), Ceres' defaults otherwise.
//
// Summary: Ceres' counts without its iteration 0 (a step that meets the
// function or parameter tolerance is discarded and not counted, as Ceres
// does); initial and final cost as Ceres reports them (with the cost of
// residual blocks that have no free parameter); times: structure = building
// the problem + Ceres' preprocessing, evaluation = residuals and Jacobians,
// factorization = its linear solver (Schur complement and factorization),
// schur 0; reduced_system_size = the tangent sizes of the free non-point
// blocks. Unlike the own solver's, its result depends on the thread count
// and on where the heap put the points (Ceres orders an elimination group by
// address): the same minimum, not the same bits.
#pragma once

#include <ceres/problem.h>
#include <ceres/ordered_groups.h>

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "src/solvers/bundle_solver.h"

namespace rig_calibrator {

class CeresBundleSolver final : public BundleSolver {
 public:
  explicit CeresBundleSolver(const BundleSolverOptions& options);

  void AddParameterBlock(double* values, int size,
                         const ceres::Manifold* manifold, int group) override;
  void Reserve(size_t num_residual_blocks, size_t num_points) override;
  void AddPoint(double* values) override;
  size_t AddResidualBlock(const ceres::CostFunction* cost,
                          const ceres::LossFunction* loss,
                          const std::vector<double*>& parameters) override;
  void SetResidualBlockActive(size_t index, bool active) override;
  void SetPointHeld(const double* values, bool held) override;
  void SetFunctionTolerance(double tolerance) override;
  // After a failure, the values are the initial ones (Ceres restores them).
  void Solve(BundleSolverSummary* summary) override;

 private:
  struct Block {
    int size = 0;
    const ceres::Manifold* manifold = nullptr;
  };
  struct Residual {
    const ceres::CostFunction* cost = nullptr;
    const ceres::LossFunction* loss = nullptr;
    std::vector<double*> parameters;
    bool active = true;
  };

  // The problem Solve solves (see the top), with its SPARSE_SCHUR ordering
  // (null without a free point); counts into `summary` when not null.
  void BuildProblem(ceres::Problem* problem,
                    std::shared_ptr<ceres::ParameterBlockOrdering>* ordering,
                    BundleSolverSummary* summary) const;

  BundleSolverOptions options_;
  std::unordered_map<const double*, Block> blocks_;
  // Per point: held (SetPointHeld).
  std::unordered_map<const double*, bool> point_held_;
  std::vector<Residual> residuals_;
};

}  // namespace rig_calibrator
