// rig_calibrator_lab: the lab around rig_calibrator, not shipped with it.
//
//   rig_calibrator_lab synthetic | render ...      data to calibrate
//   rig_calibrator_lab benchmark | benchmark_runtime | benchmark_localization
//                      | benchmark_colmap_rig_ba ... experiments, benchmarks
//
// `rig_calibrator_lab help` lists all.
#include "colmap_ext/lab_commands/lab_commands.h"

int main(int argc, char** argv) {
  return rig_calibrator::RunRigCalibratorLab("rig_calibrator_lab", argc, argv);
}
