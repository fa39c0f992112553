// One calibration of a synthetic recording as every experiment runs it: the
// method's pipeline on one thread (the experiments run calibrations in
// parallel), quiet, with a given seed; the known* methods are given the true
// intrinsics (the paper gives Inf+K and Inf+K+RI Kalibr's).
#pragma once

#include "src/calibration/pipeline.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

struct ExperimentCalibration {
  bool success = false;  // CalibrateRig returned true
  RigCalibration calibration;
  PipelineReport report;
};

ExperimentCalibration CalibrateSyntheticRig(const SyntheticRig& rig,
                                            CalibrationMethod method,
                                            unsigned int seed);

}  // namespace rig_calibrator
