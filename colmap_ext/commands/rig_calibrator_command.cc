#include "colmap_ext/commands/rig_calibrator_command.h"

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <utility>
#include <vector>

#include "colmap_ext/commands/commands.h"
#include "colmap_ext/commands/guarded_run.h"
#include "colmap_ext/lab_commands/render_command.h"

namespace rig_calibrator {
namespace {

using Command = std::function<int(int, char**)>;

const std::vector<std::pair<std::string, std::pair<Command, std::string>>>&
Commands() {
  static const std::vector<
      std::pair<std::string, std::pair<Command, std::string>>>
      commands = {
          {"calibrate",
           {&RunCalibrate,
            "calibrate a rig against a COLMAP map (the default command)"}},
          {"evaluate",
           {&RunEvaluate,
            "compare a calibration with a reference calibration"}},
          {"report",
           {&RunReport, "rebuild report.html in a calibration output folder"}},
          {"synthetic",
           {&RunSynthetic,
            "write a synthetic rig dataset with exact ground truth"}},
          {"render",
           {&RunRender,
            "render images of a textured scene for a map and a rig"}},
          {"benchmark",
           {&RunBenchmark,
            "robustness of the methods on short sequences (paper 5.3)"}},
          {"benchmark_runtime",
           {&RunRuntimeBenchmark,
            "time and memory of the calibration and the localization"}},
          {"benchmark_localization",
           {&RunLocalizationBenchmark,
            "localization throughput on a COLMAP map"}},
          {"benchmark_colmap_rig_ba",
           {&RunColmapRigBaBenchmark,
            "final bundle adjustment vs COLMAP's rig_bundle_adjuster"}},
      };
  return commands;
}

int ShowHelp(const std::string& program) {
  std::cout << "rig_calibrator: multi-camera rig calibration against a COLMAP "
               "map (Lin et al., ECCV 2020)\n\n"
               "Usage:\n"
            << "  " << program
            << " [calibrate] --database_path DB --image_path IMAGES "
               "--input_path MAP --output_path OUT [options]\n"
            << "  " << program << " <command> [options]\n"
            << "  " << program << " <command> --help\n\n"
            << "Commands:\n";
  for (const auto& [name, command] : Commands()) {
    std::cout << "  " << name
              << std::string(std::max<int>(1, 19 - name.size()), ' ')
              << command.second << "\n";
  }
  return EXIT_SUCCESS;
}

// Dispatches to the sub-command (see RunRigCalibrator).
int DispatchCommand(const std::string& program, int argc, char** argv) {
  if (argc == 1) return ShowHelp(program);
  const std::string first = argv[1];
  if (first == "help" || first == "commands") return ShowHelp(program);
  // Options without a command name go to the default command, so
  // `rig_calibrator -h` shows the calibration options.
  if (!first.empty() && first[0] == '-') return RunCalibrate(argc, argv);
  for (const auto& [name, command] : Commands()) {
    if (name == first) {
      argv[1] = argv[0];
      return command.first(argc - 1, argv + 1);
    }
  }
  std::cerr << "ERROR: unknown command `" << first << "`; run `" << program
            << " help` for the list." << std::endl;
  return EXIT_FAILURE;
}

}  // namespace

int RunRigCalibrator(const std::string& program, int argc, char** argv) {
  InitializeLogging(argv);
  return RunGuarded([&] { return DispatchCommand(program, argc, argv); });
}

}  // namespace rig_calibrator
