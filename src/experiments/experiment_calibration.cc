#include "src/experiments/experiment_calibration.h"

namespace rig_calibrator {

ExperimentCalibration CalibrateSyntheticRig(const SyntheticRig& rig,
                                            CalibrationMethod method,
                                            unsigned int seed) {
  PipelineOptions pipeline;
  pipeline.method = method;
  pipeline.print_progress = false;
  pipeline.num_threads = 1;
  pipeline.seed = seed;
  ExperimentCalibration result;
  if (UsesKnownIntrinsics(method)) {
    SyntheticRig known = rig;
    SetKnownIntrinsics(&known);
    result.success = CalibrateRig(pipeline, known.dataset, &result.calibration,
                                  &result.report);
  } else {
    result.success = CalibrateRig(pipeline, rig.dataset, &result.calibration,
                                  &result.report);
  }
  return result;
}

}  // namespace rig_calibrator
