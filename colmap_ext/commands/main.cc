// rig_calibrator: calibrates a multi-camera rig against a COLMAP map.
//
//   rig_calibrator [calibrate] --database_path ... --image_path ...
//                  --input_path ... --output_path ...
//   rig_calibrator evaluate ...
//   rig_calibrator report --calibration_path ...
//
// The first form is the default command; `rig_calibrator help` lists all.
// The same commands are `colmap rig_calibrator ...` of the extended colmap
// executable (colmap_main.cc). Synthetic data, rendering and benchmarks are
// the lab's (rig_calibrator_lab, colmap_ext/lab_commands/main.cc).
#include "colmap_ext/commands/rig_calibrator_command.h"

int main(int argc, char** argv) {
  return rig_calibrator::RunRigCalibrator("rig_calibrator", argc, argv);
}
