// The calibration-core measurement of the runtime benchmark: CalibrateRig
// (every stage the pipeline reports, wall and CPU time) on a synthetic ring
// rig, and the accuracy of the result against the truth as a sanity check.
#pragma once

#include <string>

#include "colmap_ext/benchmarks/runtime_benchmark.h"
#include "colmap_ext/benchmarks/runtime_benchmark_options.h"

namespace rig_calibrator {

// One run with `num_framesets` framesets of a ring of `num_cameras` cameras
// (ring5's layout) and the data of options.data. False with *error for
// invalid options; a failed calibration is a result (runtime->success).
bool MeasureCalibration(const RuntimeBenchmarkOptions& options,
                        int num_framesets, int num_cameras,
                        CalibrationRuntime* runtime, std::string* error);

}  // namespace rig_calibrator
