// rig_calibrator: calibrates a multi-camera rig against a COLMAP map.
//
//   rig_calibrator [calibrate] --database_path ... --image_path ...
//                  --input_path ... --output_path ...
//   rig_calibrator evaluate ...
//   rig_calibrator synthetic | render | benchmark | benchmark_runtime ...
//
// The first form is the default command; `rig_calibrator help` lists all.
#include <algorithm>
#include <cstring>
#include <functional>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "colmap_ext/commands/commands.h"
#include "colmap_ext/commands/render_command.h"

namespace {

using Command = std::function<int(int, char**)>;

const std::vector<std::pair<std::string, std::pair<Command, std::string>>>&
Commands() {
  static const std::vector<
      std::pair<std::string, std::pair<Command, std::string>>>
      commands = {
          {"calibrate",
           {&rig_calibrator::RunCalibrate,
            "calibrate a rig against a COLMAP map (the default command)"}},
          {"evaluate",
           {&rig_calibrator::RunEvaluate,
            "compare a calibration with a reference calibration"}},
          {"synthetic",
           {&rig_calibrator::RunSynthetic,
            "write a synthetic rig dataset with exact ground truth"}},
          {"render",
           {&rig_calibrator::RunRender,
            "render images of a textured scene for a map and a rig"}},
          {"benchmark",
           {&rig_calibrator::RunBenchmark,
            "robustness of the methods on short sequences (paper 5.3)"}},
          {"benchmark_runtime",
           {&rig_calibrator::RunRuntimeBenchmark,
            "time and memory of the calibration and the localization"}},
      };
  return commands;
}

int ShowHelp() {
  std::cout << "rig_calibrator: multi-camera rig calibration against a COLMAP "
               "map (Lin et al., ECCV 2020)\n\n"
               "Usage:\n"
               "  rig_calibrator [calibrate] --database_path DB --image_path "
               "IMAGES --input_path MAP --output_path OUT [options]\n"
               "  rig_calibrator <command> [options]\n"
               "  rig_calibrator <command> --help\n\n"
               "Commands:\n";
  for (const auto& [name, command] : Commands()) {
    std::cout << "  " << name
              << std::string(std::max<int>(1, 19 - name.size()), ' ')
              << command.second << "\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace

int main(int argc, char** argv) {
  rig_calibrator::InitializeLogging(argv);
  if (argc == 1) return ShowHelp();
  const std::string first = argv[1];
  if (first == "help" || first == "commands") return ShowHelp();
  // Options without a command name go to the default command, so
  // `rig_calibrator -h` shows the calibration options.
  if (!first.empty() && first[0] == '-') {
    return rig_calibrator::RunCalibrate(argc, argv);
  }
  for (const auto& [name, command] : Commands()) {
    if (name == first) {
      argv[1] = argv[0];
      return command.first(argc - 1, argv + 1);
    }
  }
  std::cerr << "ERROR: unknown command `" << first
            << "`; run `rig_calibrator help` for the list." << std::endl;
  return EXIT_FAILURE;
}
