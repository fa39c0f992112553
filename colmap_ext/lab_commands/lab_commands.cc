#include "colmap_ext/lab_commands/lab_commands.h"

#include "colmap_ext/commands/command_table.h"
#include "colmap_ext/lab_commands/render_command.h"

namespace rig_calibrator {

int RunRigCalibratorLab(const std::string& program, int argc, char** argv) {
  static const CommandTable table = {
      "rig_calibrator_lab: synthetic data, rendering and benchmarks of "
      "rig_calibrator",
      {{"synthetic", &RunSynthetic,
        "write a synthetic rig dataset with exact ground truth"},
       {"render", &RunRender,
        "render images of a textured scene for a map and a rig"},
       {"benchmark", &RunBenchmark,
        "robustness of the methods on short sequences (paper 5.3)"},
       {"benchmark_runtime", &RunRuntimeBenchmark,
        "time and memory of the calibration and the localization"},
       {"benchmark_localization", &RunLocalizationBenchmark,
        "localization throughput on a COLMAP map"},
       {"benchmark_colmap_rig_ba", &RunColmapRigBaBenchmark,
        "final bundle adjustment vs COLMAP's rig_bundle_adjuster"}}};
  return RunCommandTable(table, program, argc, argv);
}

}  // namespace rig_calibrator
