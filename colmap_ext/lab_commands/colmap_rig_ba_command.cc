// `rig_calibrator_lab benchmark_colmap_rig_ba`: this project's final bundle
// adjustment against COLMAP 3.8's `rig_bundle_adjuster` on the same problem
// from the same start, in one run (colmap_ext/benchmarks/
// colmap_rig_ba_comparison.h):
//
//   rig_calibrator_lab benchmark_colmap_rig_ba --output_path DIR
//       [--framesets 100,500] [--cameras 10] [--quick 1]
//
// DIR gets colmap_rig_ba.md (the table, with the machine's load) and
// colmap_rig_ba.csv. --quick: 10 framesets x 5 cameras (ctest).
#include <iostream>

#include "colmap_ext/benchmarks/colmap_rig_ba_comparison.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/lab_commands/lab_commands.h"
#include "colmap_ext/lab_commands/synthetic_data_options.h"

namespace rig_calibrator {

int RunColmapRigBaBenchmark(int argc, char** argv) {
  namespace po = boost::program_options;
  ColmapRigBaComparisonOptions options;
  bool quick = false;
  po::options_description description =
      CommandOptions("rig_calibrator_lab benchmark_colmap_rig_ba options");
  AddRequiredOption(&description, "output_path", &options.output_path,
                    "results folder (created if needed): colmap_rig_ba.md, "
                    "colmap_rig_ba.csv");
  AddOption(&description, "framesets", &options.framesets,
            "frameset counts (comma-separated)");
  AddOption(&description, "cameras", &options.cameras,
            "camera counts of the ring rig (comma-separated)");
  AddOption(&description, "quick", &quick,
            "10 framesets x 5 cameras, whatever --framesets and --cameras");
  AddOption(&description, "colmap_executable", &options.colmap_executable,
            "the extended colmap (empty: colmap beside this executable)");
  AddOption(&description, "function_tolerance", &options.function_tolerance,
            "both solvers' function tolerance (AdjustRig's is fixed at "
            "1e-4: keep them equal)");
  AddOption(&description, "max_num_iterations", &options.max_num_iterations,
            "both solvers' iteration limit");
  AddOption(&description, "loss_scale_px", &options.loss_scale_px,
            "AdjustRig's Cauchy scale (large: nearly COLMAP's trivial loss)");
  AddSyntheticDataOptions(&description, &options.data);
  AddOption(&description, "map_point_noise", &options.data.map_point_noise,
            "error of the start's map points (map units, Gaussian per "
            "coordinate)");
  AddOption(&description, "seed", &options.seed, "random seed");
  AddOption(&description, "keep_work_folder", &options.keep_work_folder,
            "keep the COLMAP models and logs (the path is printed)");
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, description,
          "rig_calibrator_lab benchmark_colmap_rig_ba: our final bundle "
          "adjustment vs COLMAP 3.8 rig_bundle_adjuster")) {
    return *exit_code;
  }
  if (quick) {
    options.framesets = "10";
    options.cameras = "5";
  }
  std::string error;
  if (!RunColmapRigBaComparison(options, &error)) {
    std::cerr << "rig_calibrator_lab benchmark_colmap_rig_ba: " << error
              << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
