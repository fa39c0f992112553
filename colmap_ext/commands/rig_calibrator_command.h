// The `rig_calibrator` command: the shipped sub-commands (calibrate,
// evaluate, report) behind one name, shared by the standalone
// `rig_calibrator` executable and `colmap rig_calibrator` of the extended
// colmap executable (colmap_main.cc).
#pragma once

#include <string>

namespace rig_calibrator {

// Runs `PROGRAM [calibrate|evaluate|report] [options]` (command_table.h): an
// option first goes to `calibrate` (so `PROGRAM -h` shows the calibration
// options).
int RunRigCalibrator(const std::string& program, int argc, char** argv);

}  // namespace rig_calibrator
