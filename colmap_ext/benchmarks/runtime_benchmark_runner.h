// The runtime benchmark's two sides. The parent runs every measurement in a
// child process (this executable again: `benchmark_runtime` with the
// parent's options plus the hidden ChildRequest options) so that each peak
// memory is the child's own, collects the results and writes runtime.md,
// runtime_calibration.csv, runtime_localization.csv and
// runtime_calibration.svg into options.output_path (created if needed;
// these files are replaced, others are left alone). A child makes one
// measurement and writes it, serialized, to request.result_path.
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/benchmarks/runtime_benchmark_options.h"

namespace rig_calibrator {

// `base_arguments`: the command line that reaches this command again
// (program name, command name, the parent's options). Returns the exit
// code: failure when a file could not be written or a run failed.
int RunRuntimeBenchmarkParent(const RuntimeBenchmarkOptions& options,
                              const std::vector<std::string>& base_arguments);

// The measurement of options.request; returns the exit code.
int RunRuntimeBenchmarkChild(const RuntimeBenchmarkOptions& options);

}  // namespace rig_calibrator
