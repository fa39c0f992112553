// The localization measurement of the runtime benchmark: MapLocalizer
// (features already in a COLMAP database) against a synthetic map
// (WriteSyntheticMapDatabase) in one mode, its recall and precision against
// the planted correspondences, then the 1D radial pose of each image.
#pragma once

#include <string>

#include "colmap_ext/benchmarks/runtime_benchmark.h"
#include "colmap_ext/benchmarks/runtime_benchmark_options.h"

namespace rig_calibrator {

// One run in `request.mode` with `request.rig_features` features per rig
// image and `request.num_checks` FLANN checks (0: the default); the
// database is written to and removed from `request.work_dir`. False with
// *error when the run could not be made.
bool MeasureLocalization(const RuntimeBenchmarkOptions& options,
                         const ChildRequest& request,
                         LocalizationRuntime* runtime, std::string* error);

}  // namespace rig_calibrator
