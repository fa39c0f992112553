#include "src/solvers/bundle_solver.h"

#include <sstream>

#include "src/solvers/bundle_levenberg_marquardt.h"
#include "src/solvers/ceres_bundle_solver.h"

namespace rig_calibrator {

std::string BundleSolverSummary::BriefReport() const {
  std::ostringstream report;
  report << "Bundle Levenberg-Marquardt: Iterations: "
         << num_successful_steps + num_unsuccessful_steps
         << ", Initial cost: " << initial_cost << ", Final cost: " << final_cost
         << ", Termination: "
         << (termination == Termination::kConvergence     ? "CONVERGENCE"
             : termination == Termination::kNoConvergence ? "NO_CONVERGENCE"
                                                          : "FAILURE")
         << " (" << message << ")";
  return report.str();
}

bool BundleSolverBackendFromName(const std::string& name,
                                 BundleSolverBackend* backend) {
  for (const BundleSolverBackend value :
       {BundleSolverBackend::kOwn, BundleSolverBackend::kCeres}) {
    if (BundleSolverBackendName(value) == name) {
      *backend = value;
      return true;
    }
  }
  return false;
}

std::string BundleSolverBackendName(BundleSolverBackend backend) {
  return backend == BundleSolverBackend::kOwn ? "own" : "ceres";
}

std::unique_ptr<BundleSolver> MakeBundleSolver(
    BundleSolverBackend backend,
    const BundleSolverOptions& options) {
  if (backend == BundleSolverBackend::kCeres) {
    return std::make_unique<CeresBundleSolver>(options);
  }
  return std::make_unique<BundleLevenbergMarquardt>(options);
}

}  // namespace rig_calibrator
