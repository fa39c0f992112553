// The lab's sub-commands, the `rig_calibrator_lab` executable (main.cc):
// synthetic data, rendered images, the paper's experiments and the
// benchmarks, which measure and feed rig_calibrator but are not part of what
// a user runs to calibrate; the shipped `rig_calibrator` and `colmap` do not
// link them. Each takes (argc, argv) as colmap_ext/commands/commands.h.
#pragma once

#include <string>

namespace rig_calibrator {

// Runs `PROGRAM <command> [options]` (colmap_ext/commands/command_table.h)
// over the sub-commands below and RunRender (render_command.h).
int RunRigCalibratorLab(const std::string& program, int argc, char** argv);

// Writes a synthetic rig dataset (2D-3D correspondences) with its ground truth.
int RunSynthetic(int argc, char** argv);

// The paper's short-sequence robustness experiment on synthetic rigs.
int RunBenchmark(int argc, char** argv);

// Time and peak memory of the calibration core and of the localization
// (runtime_benchmark_command.cc).
int RunRuntimeBenchmark(int argc, char** argv);

// Localization throughput on a COLMAP map, one configuration per run
// (localization_benchmark_command.cc).
int RunLocalizationBenchmark(int argc, char** argv);

// Our final bundle adjustment vs COLMAP 3.8's rig_bundle_adjuster on the same
// problem (colmap_rig_ba_command.cc).
int RunColmapRigBaBenchmark(int argc, char** argv);

}  // namespace rig_calibrator
