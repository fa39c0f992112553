// Internal to the rig initialization (rig_init_problem.h): the local
// optimization of paper eq. 4 that refines the best RANSAC hypothesis,
//   min_{P_i, Q_j} sum_{(i,j) used} rho(|d(T_ij, P_i Q_j)|^2),
// d as in pose_deviation_cost.h, rho a Cauchy loss of scale
// options.loss_scale.
#pragma once

#include <vector>

#include "src/calibration/rig_init_problem.h"

namespace rig_calibrator {
namespace rig_init {

// Refines the hypothesis' cameras and rig poses that the used images (per
// localized image) observe. The reference camera's pose is held at the
// identity; with radial poses each camera's tz is held at 0 and the slide of
// the rig origin along the reference axis (rig_initializer.h) is held by one
// rig pose's t_z. If the solver fails, logs a warning and leaves the
// hypothesis as it was.
void MinimizePoseDeviation(const InitProblem& problem,
                           const std::vector<char>& used,
                           Hypothesis* hypothesis);

}  // namespace rig_init
}  // namespace rig_calibrator
