// The rig_calibrator sub-commands. Each takes (argc, argv) with argv[0] the
// program name, parses colmap-style options (--name value, grouped as
// --Group.name), and returns the process exit code.
#pragma once

namespace rig_calibrator {

// glog to stderr, COLMAP's failure handler.
void InitializeLogging(char** argv);

// Localizes the rig images in a COLMAP map (or reads 2D-3D correspondences),
// calibrates the rig and writes it in COLMAP's and Kalibr's formats.
int RunCalibrate(int argc, char** argv);

// Compares a calibration (rig_config.json or camchain.yaml) with a reference.
int RunEvaluate(int argc, char** argv);

// Writes a synthetic rig dataset (2D-3D correspondences) with its ground truth.
int RunSynthetic(int argc, char** argv);

// The paper's short-sequence robustness experiment on synthetic rigs.
int RunBenchmark(int argc, char** argv);

// Rebuilds report.html in a calibration output folder (report_command.cc).
int RunReport(int argc, char** argv);

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
