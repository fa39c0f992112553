#include "src/calibration/rig_init_refinement.h"

#include <ceres/ceres.h>
#include <glog/logging.h>

#include <array>
#include <memory>

#include "src/calibration/pose_deviation_cost.h"

namespace rig_calibrator {
namespace rig_init {
namespace {

// The parameter blocks of eq. 4, (angle-axis, translation) per pose, and
// whether a residual uses them.
struct PoseParameters {
  std::vector<std::array<double, 6>> cam_from_rig;
  std::vector<std::array<double, 6>> rig_from_world;
  std::vector<char> cam_added;
  std::vector<char> rig_added;
};

// One residual per used image, and the gauge as in the header. `ordering`
// puts the rig poses in the group the Schur complement eliminates (no
// residual links two of them), the cameras in the other.
void AddResiduals(const InitProblem& problem, const std::vector<char>& used,
                  PoseParameters* parameters, ceres::Problem* ceres_problem,
                  ceres::ParameterBlockOrdering* ordering) {
  const bool radial = problem.num_rows == 2;
  ceres::LossFunction* loss = new ceres::CauchyLoss(problem.options.loss_scale);
  for (size_t k = 0; k < problem.images.size(); ++k) {
    if (!used[k]) continue;
    const LocalizedImage& image = problem.images[k];
    const double weight = problem.options.translation_weight;
    ceres::CostFunction* cost =
        radial ? PoseDeviationCost<2>::Create(image.cam_from_world,
                                              image.scene_center, weight)
               : PoseDeviationCost<3>::Create(image.cam_from_world,
                                              image.scene_center, weight);
    ceres_problem->AddResidualBlock(
        cost, loss, parameters->cam_from_rig[image.camera].data(),
        parameters->rig_from_world[image.frameset].data());
    parameters->cam_added[image.camera] = 1;
    parameters->rig_added[image.frameset] = 1;
  }
  if (ceres_problem->NumResidualBlocks() == 0) return;

  bool tz_gauge_held = false;
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (!parameters->rig_added[j]) continue;
    ordering->AddElementToGroup(parameters->rig_from_world[j].data(), 0);
    if (radial && !tz_gauge_held) {
      ceres_problem->SetManifold(parameters->rig_from_world[j].data(),
                                 new ceres::SubsetManifold(6, {5}));
      tz_gauge_held = true;
    }
  }
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (!parameters->cam_added[i]) continue;
    ordering->AddElementToGroup(parameters->cam_from_rig[i].data(), 1);
    if (i == problem.reference_camera) {
      ceres_problem->SetParameterBlockConstant(
          parameters->cam_from_rig[i].data());
    } else if (radial) {
      ceres_problem->SetManifold(parameters->cam_from_rig[i].data(),
                                 new ceres::SubsetManifold(6, {5}));
    }
  }
}

}  // namespace

void MinimizePoseDeviation(const InitProblem& problem,
                           const std::vector<char>& used,
                           Hypothesis* hypothesis) {
  PoseParameters parameters;
  parameters.cam_from_rig.resize(problem.num_cameras);
  parameters.rig_from_world.resize(problem.num_framesets);
  parameters.cam_added.assign(problem.num_cameras, 0);
  parameters.rig_added.assign(problem.num_framesets, 0);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (hypothesis->cam_from_rig[i]) {
      parameters.cam_from_rig[i] =
          ToAngleAxisTranslation(*hypothesis->cam_from_rig[i]);
    }
  }
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (hypothesis->rig_from_world[j]) {
      parameters.rig_from_world[j] =
          ToAngleAxisTranslation(*hypothesis->rig_from_world[j]);
    }
  }

  ceres::Problem ceres_problem;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  AddResiduals(problem, used, &parameters, &ceres_problem, ordering.get());
  if (ceres_problem.NumResidualBlocks() == 0) return;

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = ordering;
  solver_options.max_num_iterations = 100;
  // One thread: the Schur elimination accumulates in thread order, which
  // would make the result vary in the last bits; the problem is small.
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary solver_summary;
  ceres::Solve(solver_options, &ceres_problem, &solver_summary);
  if (!solver_summary.IsSolutionUsable()) {
    LOG(WARNING) << "InitializeRig: the refinement of eq. 4 failed ("
                 << solver_summary.message << "); keeping the RANSAC rig";
    return;
  }
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (parameters.cam_added[i]) {
      hypothesis->cam_from_rig[i] =
          FromAngleAxisTranslation(parameters.cam_from_rig[i]);
    }
  }
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (parameters.rig_added[j]) {
      hypothesis->rig_from_world[j] =
          FromAngleAxisTranslation(parameters.rig_from_world[j]);
    }
  }
}

}  // namespace rig_init
}  // namespace rig_calibrator
