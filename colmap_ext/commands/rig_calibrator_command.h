// The `rig_calibrator` command: its sub-commands behind one name, shared by
// the standalone `rig_calibrator` executable and `colmap rig_calibrator` of
// the extended colmap executable (colmap_main.cc).
#pragma once

#include <string>

namespace rig_calibrator {

// Runs `PROGRAM [calibrate|evaluate|report|synthetic|render|benchmark|
// benchmark_runtime] [options]` with argv[0] the program name: no argument,
// `help` or `commands` lists the sub-commands, an option first goes to
// `calibrate` (so `PROGRAM -h` shows the calibration options). `program` is
// how the user invoked the command ("rig_calibrator" or "colmap
// rig_calibrator"), used in the usage and error messages. Returns the exit
// code; an exception that escapes a sub-command ends it with a one-line
// error and EXIT_FAILURE (RunGuarded).
int RunRigCalibrator(const std::string& program, int argc, char** argv);

}  // namespace rig_calibrator
