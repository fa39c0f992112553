#include "colmap_ext/commands/rig_calibrator_command.h"

#include "colmap_ext/commands/command_table.h"
#include "colmap_ext/commands/commands.h"

namespace rig_calibrator {

int RunRigCalibrator(const std::string& program, int argc, char** argv) {
  static const CommandTable table = {
      "rig_calibrator: multi-camera rig calibration against a COLMAP map "
      "(Lin et al., ECCV 2020)",
      {{"calibrate", &RunCalibrate,
        "calibrate a rig against a COLMAP map (the default command)"},
       {"evaluate", &RunEvaluate,
        "compare a calibration with a reference calibration"},
       {"report", &RunReport,
        "rebuild report.html in a calibration output folder"}},
      "calibrate",
      "--database_path DB --image_path IMAGES --input_path MAP "
      "--output_path OUT [options]"};
  return RunCommandTable(table, program, argc, argv);
}

}  // namespace rig_calibrator
