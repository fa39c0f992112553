#include "src/solvers/ceres_bundle_solver.h"

#include <ceres/ceres.h>
#include <glog/logging.h>

#include <algorithm>
#include <chrono>
#include <thread>

namespace rig_calibrator {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

// Ceres' group of the eliminated blocks, and of the others.
constexpr int kPointGroup = 0;
constexpr int kCameraSideGroup = 1;

// The problems' options: Ceres only reads the costs, losses and
// manifolds; its interface takes them non-const.
ceres::Problem::Options NonOwningProblemOptions() {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return problem_options;
}

}  // namespace

CeresBundleSolver::CeresBundleSolver(
    const BundleSolverOptions& options)
    : options_(options) {}

void CeresBundleSolver::AddParameterBlock(double* values, int size,
                                          const ceres::Manifold* manifold,
                                          int /*group*/) {
  CHECK(blocks_.emplace(values, Block{size, manifold}).second)
      << "a parameter block added twice";
}

void CeresBundleSolver::Reserve(size_t num_residual_blocks, size_t num_points) {
  residuals_.reserve(num_residual_blocks);
  point_held_.reserve(num_points);
}

void CeresBundleSolver::AddPoint(double* values) {
  CHECK(point_held_.emplace(values, false).second) << "a point added twice";
}

size_t CeresBundleSolver::AddResidualBlock(
    const ceres::CostFunction* cost, const ceres::LossFunction* loss,
    const std::vector<double*>& parameters) {
  CHECK_EQ(cost->num_residuals(), 2);
  CHECK_EQ(parameters.size(), cost->parameter_block_sizes().size());
  residuals_.push_back({cost, loss, parameters, true});
  return residuals_.size() - 1;
}

void CeresBundleSolver::SetResidualBlockActive(size_t index, bool active) {
  CHECK_LT(index, residuals_.size());
  residuals_[index].active = active;
}

void CeresBundleSolver::SetPointHeld(const double* values, bool held) {
  const auto point = point_held_.find(values);
  CHECK(point != point_held_.end()) << "not a point of the problem";
  point->second = held;
}

void CeresBundleSolver::SetFunctionTolerance(double tolerance) {
  options_.function_tolerance = tolerance;
}

void CeresBundleSolver::BuildProblem(
    ceres::Problem* problem,
    std::shared_ptr<ceres::ParameterBlockOrdering>* ordering,
    BundleSolverSummary* summary) const {
  BundleSolverSummary counts;
  for (const Residual& residual : residuals_) {
    if (!residual.active) continue;
    problem->AddResidualBlock(const_cast<ceres::CostFunction*>(residual.cost),
                              const_cast<ceres::LossFunction*>(residual.loss),
                              residual.parameters);
    ++counts.num_residual_blocks;
  }
  auto groups = std::make_shared<ceres::ParameterBlockOrdering>();
  std::vector<double*> problem_blocks;
  problem->GetParameterBlocks(&problem_blocks);
  bool has_free_point = false;
  for (double* values : problem_blocks) {
    const auto block = blocks_.find(values);
    const auto point = point_held_.find(values);
    if (block != blocks_.end()) {
      CHECK_EQ(problem->ParameterBlockSize(values), block->second.size);
      if (block->second.manifold != nullptr) {
        problem->SetManifold(
            values, const_cast<ceres::Manifold*>(block->second.manifold));
      }
      counts.reduced_system_size += problem->ParameterBlockTangentSize(values);
      groups->AddElementToGroup(values, kCameraSideGroup);
    } else if (point != point_held_.end() && !point->second) {
      has_free_point = true;
      groups->AddElementToGroup(values, kPointGroup);
    } else {
      problem->SetParameterBlockConstant(values);
      groups->AddElementToGroup(values, kCameraSideGroup);
    }
  }
  counts.num_points = static_cast<int>(
      std::count_if(point_held_.begin(), point_held_.end(),
                    [](const auto& point) { return !point.second; }));
  *ordering = has_free_point ? groups : nullptr;
  if (summary != nullptr) {
    summary->num_residual_blocks = counts.num_residual_blocks;
    summary->reduced_system_size = counts.reduced_system_size;
    summary->num_points = counts.num_points;
  }
}

void CeresBundleSolver::Solve(BundleSolverSummary* summary) {
  using Termination = BundleSolverSummary::Termination;
  const auto start_time = std::chrono::steady_clock::now();
  *summary = BundleSolverSummary();
  ceres::Problem problem(NonOwningProblemOptions());
  std::shared_ptr<ceres::ParameterBlockOrdering> ordering;
  BuildProblem(&problem, &ordering, summary);
  const double build_seconds = SecondsSince(start_time);

  ceres::Solver::Options solver_options;
  solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  solver_options.linear_solver_type = ceres::SPARSE_SCHUR;
  if (ordering != nullptr) solver_options.linear_solver_ordering = ordering;
  solver_options.max_num_iterations = options_.max_num_iterations;
  solver_options.function_tolerance = options_.function_tolerance;
  solver_options.parameter_tolerance = options_.parameter_tolerance;
  solver_options.gradient_tolerance = options_.gradient_tolerance;
  solver_options.initial_trust_region_radius =
      options_.initial_trust_region_radius;
  solver_options.num_threads =
      options_.num_threads > 0
          ? options_.num_threads
          : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  solver_options.minimizer_progress_to_stdout = options_.print_progress;
  solver_options.logging_type =
      options_.print_progress ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver_options, &problem, &ceres_summary);

  summary->termination =
      !ceres_summary.IsSolutionUsable() ? Termination::kFailure
      : ceres_summary.termination_type == ceres::NO_CONVERGENCE
          ? Termination::kNoConvergence
          : Termination::kConvergence;
  summary->message = ceres_summary.message;
  for (const ceres::IterationSummary& iteration : ceres_summary.iterations) {
    if (iteration.iteration == 0) continue;
    ++(iteration.step_is_successful ? summary->num_successful_steps
                                    : summary->num_unsuccessful_steps);
  }
  summary->initial_cost = ceres_summary.initial_cost;
  summary->final_cost = ceres_summary.final_cost;
  summary->structure_seconds =
      build_seconds + ceres_summary.preprocessor_time_in_seconds;
  summary->evaluation_seconds =
      ceres_summary.residual_evaluation_time_in_seconds +
      ceres_summary.jacobian_evaluation_time_in_seconds;
  summary->factorization_seconds = ceres_summary.linear_solver_time_in_seconds;
  summary->seconds = SecondsSince(start_time);
}

}  // namespace rig_calibrator
