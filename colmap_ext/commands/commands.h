// The rig_calibrator sub-commands. Each takes (argc, argv) with argv[0] the
// program name, parses colmap-style options (--name value, grouped as
// --Group.name), and returns the process exit code. The lab's sub-commands
// are in colmap_ext/lab_commands/lab_commands.h.
#pragma once

namespace rig_calibrator {

// glog to stderr, COLMAP's failure handler.
void InitializeLogging(char** argv);

// Localizes the rig images in a COLMAP map (or reads 2D-3D correspondences),
// calibrates the rig and writes it in COLMAP's and Kalibr's formats.
int RunCalibrate(int argc, char** argv);

// Compares a calibration (rig_config.json or camchain.yaml) with a reference.
int RunEvaluate(int argc, char** argv);

// Rebuilds report.html in a calibration output folder (report_command.cc).
int RunReport(int argc, char** argv);

}  // namespace rig_calibrator
