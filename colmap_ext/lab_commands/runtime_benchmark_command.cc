// `rig_calibrator_lab benchmark_runtime`: how long the calibration takes and
// how much memory it needs (issue targets: the calibration core for 500
// framesets x 10 cameras x ~300 correspondences in under 60 s on 2 cores,
// growing about linearly with the framesets; localization of at least 5 rig
// images per second against a 300-image map).
//
//  * Calibration core: CalibrateRig (every stage the pipeline reports) on
//    synthetic rigs (ring5, or its 10-camera ring) for each frameset count x
//    camera count, in the scenario (0.5 px noise, 30 % wrong matches,
//    10 % missing images); colmap_ext/benchmarks/calibration_measurement.h.
//  * Localization: MapLocalizer (features already in a COLMAP database) in
//    direct and retrieval mode against a synthetic 300-image map, then the
//    1D radial pose of each image; localization_measurement.h.
//
// Every measurement runs in a child process (this executable again, with
// hidden --child options) so that its peak memory is its own
// (runtime_benchmark_runner.h). This file declares the options only.
#include <boost/program_options.hpp>
#include <string>
#include <vector>

#include "colmap_ext/benchmarks/runtime_benchmark_options.h"
#include "colmap_ext/benchmarks/runtime_benchmark_runner.h"
#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/lab_commands/lab_commands.h"
#include "colmap_ext/lab_commands/synthetic_data_options.h"

namespace rig_calibrator {
namespace {

namespace po = boost::program_options;

void AddCalibrationRunOptions(po::options_description* description,
                              RuntimeBenchmarkOptions* o) {
  AddRequiredOption(description, "output_path", &o->output_path,
                    "results folder (created if needed): runtime.md, "
                    "runtime_calibration.csv/.svg, runtime_localization.csv");
  AddOption(description, "framesets", &o->framesets,
            "frameset counts of the calibration runs");
  AddOption(description, "cameras", &o->cameras,
            "camera counts of the calibration runs (a ring of N cameras, "
            "ring5's layout)");
  AddOption(description, "method", &o->method, "calibration method");
  AddOption(description, "refine_points", &o->refine_points,
            "the final bundle adjustment also refines the map points (the "
            "calibrate command's default)");
  AddSyntheticDataOptions(description, &o->data);
  AddOption(description, "map_point_noise", &o->data.map_point_noise,
            "error of the map points given to the calibration (map units, "
            "Gaussian per coordinate)");
  AddOption(description, "num_threads", &o->num_threads,
            "threads (-1: all cores)");
  AddOption(description, "seed", &o->seed, "random seed");
  AddOption(description, "baseline_executable", &o->baseline_executable,
            "another rig_calibrator build: each calibration run is also made "
            "with it, first, for a before/after table");
  AddOption(description, "repeats", &o->repeats,
            "runs per calibration configuration and build, before and after "
            "alternating; the tables give each stage's median");
  AddOption(description, "calibration", &o->calibration,
            "measure the calibration core");
  AddOption(description, "localization", &o->localization,
            "measure the localization");
}

void AddLocalizationRunOptions(po::options_description* description,
                               RuntimeBenchmarkOptions* o) {
  AddOption(description, "map_images", &o->map_images,
            "map images of the localization benchmark");
  AddOption(description, "map_features", &o->map_features,
            "features per map image");
  AddOption(description, "map_points_per_image", &o->map_points_per_image,
            "features per map image that have a 3D point");
  AddOption(description, "rig_features", &o->rig_features,
            "features per rig image (comma-separated: one direct-mode run "
            "each; retrieval runs at the first)");
  AddOption(description, "rig_images", &o->rig_images,
            "rig images localized in direct mode");
  AddOption(description, "num_checks", &o->num_checks,
            "FLANN leaf checks of the direct index (comma-separated: one "
            "direct run each; retrieval runs at the first)");
  AddOption(description, "retrieval_images", &o->retrieval_images,
            "rig images localized in retrieval mode (it matches images: "
            "slow)");
}

// The options the parent adds for a child (RunRuntimeBenchmarkParent).
po::options_description ChildOptions(ChildRequest* request) {
  po::options_description hidden("child process options");
  AddUnsetOption(&hidden, "child", &request->child, "");
  AddUnsetOption(&hidden, "child_result", &request->result_path, "");
  AddUnsetOption(&hidden, "child_framesets", &request->framesets, "");
  AddUnsetOption(&hidden, "child_cameras", &request->cameras, "");
  AddUnsetOption(&hidden, "child_rig_features", &request->rig_features, "");
  AddUnsetOption(&hidden, "child_num_checks", &request->num_checks, "");
  AddUnsetOption(&hidden, "child_mode", &request->mode, "");
  AddUnsetOption(&hidden, "child_work_dir", &request->work_dir, "");
  return hidden;
}

}  // namespace

int RunRuntimeBenchmark(int argc, char** argv) {
  RuntimeBenchmarkOptions options;
  po::options_description description =
      CommandOptions("rig_calibrator_lab benchmark_runtime options");
  AddCalibrationRunOptions(&description, &options);
  AddLocalizationRunOptions(&description, &options);
  po::options_description all;
  all.add(description).add(ChildOptions(&options.request));
  // The help shows the public options only.
  bool wants_help = false;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    wants_help = wants_help || argument == "-h" || argument == "--help";
  }
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, wants_help ? description : all,
          "rig_calibrator_lab benchmark_runtime: time and memory of the "
          "calibration core and of the localization")) {
    return *exit_code;
  }
  if (!options.request.child.empty()) {
    return RunRuntimeBenchmarkChild(options);
  }
  // Children get the same options: program name, command, then argv[1..].
  std::vector<std::string> base_arguments = {argv[0], "benchmark_runtime"};
  for (int i = 1; i < argc; ++i) base_arguments.push_back(argv[i]);
  return RunRuntimeBenchmarkParent(options, base_arguments);
}

}  // namespace rig_calibrator
