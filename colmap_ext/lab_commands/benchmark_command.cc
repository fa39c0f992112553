// `rig_calibrator_lab benchmark`: the paper's experiments on synthetic rigs.
//  --experiment short_sequence (default): one robustness table (paper §5.3)
//    for one preset, scene and difficulty, on the terminal and, with
//    --output_path, in that Markdown file.
//  --experiment accuracy | robustness | all: the accuracy table (§5.2,
//    Table 1), the robustness tables (§5.3, Table 3) and the distributions
//    of the initial errors (§5.4, Fig. 6) as Markdown, CSV and SVG files in
//    the folder --output_path (created if needed; files are replaced).
#include <colmap/util/misc.h>
#include <glog/logging.h>

#include <boost/filesystem.hpp>
#include <iomanip>
#include <iostream>

#include "colmap_ext/commands/command_options.h"
#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/lab_commands/lab_commands.h"
#include "colmap_ext/lab_commands/robustness_figures.h"
#include "src/experiments/accuracy_experiment.h"
#include "src/experiments/robustness_experiment.h"
#include "src/experiments/short_sequence_experiment.h"

namespace rig_calibrator {
namespace {

// Values given on the command line override the difficulty's; negative =
// not given.
struct DataOverrides {
  int points_per_image = -1;
  double noise_px = -1, outlier_ratio = -1, missing_image_ratio = -1;
  double feature_window = -1;
  int frameset_stride = -1;

  // The options that set them, prefixed "short_sequence: " in the help.
  void AddOptions(boost::program_options::options_description* description) {
    const std::string only = "short_sequence: ";
    AddUnsetOption(description, "points_per_image", &points_per_image,
                   only + "correspondences per image");
    AddUnsetOption(description, "noise_px", &noise_px,
                   only + "pixel noise (standard deviation)");
    AddUnsetOption(description, "outlier_ratio", &outlier_ratio,
                   only + "share of wrong 2D-3D matches");
    AddUnsetOption(description, "missing_image_ratio", &missing_image_ratio,
                   only + "share of images dropped");
    AddUnsetOption(description, "feature_window", &feature_window,
                   only +
                       "side of the per-image feature window (share of "
                       "the image)");
    AddUnsetOption(description, "frameset_stride", &frameset_stride,
                   only + "recording framesets between sequence ones");
  }

  void Apply(BenchmarkDifficulty* difficulty) const {
    if (points_per_image >= 0) difficulty->points_per_image = points_per_image;
    if (noise_px >= 0) difficulty->noise_px = noise_px;
    if (outlier_ratio >= 0) difficulty->outlier_ratio = outlier_ratio;
    if (missing_image_ratio >= 0) {
      difficulty->missing_image_ratio = missing_image_ratio;
    }
    if (feature_window >= 0) difficulty->feature_window = feature_window;
    if (frameset_stride >= 0) difficulty->frameset_stride = frameset_stride;
  }
};

bool WriteResult(const std::string& folder, const std::string& name,
                 const std::string& contents) {
  std::string error;
  const std::string path = (boost::filesystem::path(folder) / name).string();
  if (!WriteFileAtomically(path, contents, &error)) {
    PrintError(error);
    return false;
  }
  std::cout << "  wrote " << path << std::endl;
  return true;
}

bool RunAccuracy(const AccuracyOptions& options, const std::string& folder) {
  std::cout << "Accuracy (paper Table 1): " << options.presets.size()
            << " rigs x " << options.scenes.size() << " scenes x "
            << options.methods.size() << " methods, " << options.num_framesets
            << " framesets each" << std::endl;
  const std::vector<AccuracyRun> runs = RunAccuracyExperiment(options);
  for (const AccuracyRun& run : runs) {
    if (!run.success) {
      std::cout << "  " << RigPresetName(run.preset) << " / " << run.scene
                << " / " << CalibrationMethodName(run.method)
                << " failed: " << run.error << std::endl;
    }
  }
  const std::string paper_table = FormatAccuracyPaperTable(runs);
  const std::string table = FormatAccuracyTable(runs);
  std::cout << paper_table << std::endl;
  std::ostringstream markdown;
  markdown << "# Accuracy on full synthetic recordings (paper Table 1)\n\n"
           << options.num_framesets << " framesets per recording, "
           << options.recording.points_per_image
           << " correspondences per image, " << options.recording.noise_px
           << " px noise, " << 100 * options.recording.outlier_ratio
           << " % wrong matches, "
           << 100 * options.recording.missing_image_ratio
           << " % missing images. Errors against the true calibration; "
              "the rig is aligned on all cameras' orientations, without "
              "scale. The methods with given intrinsics (known*) are given "
              "the true intrinsics.\n\n## Mean over the cameras\n\n"
           << paper_table << "\n## Mean / max over the cameras\n\n"
           << table;
  return WriteResult(folder, "accuracy.md", markdown.str()) &&
         WriteResult(folder, "accuracy_summary.csv",
                     AccuracySummaryCsv(runs)) &&
         WriteResult(folder, "accuracy_per_camera.csv",
                     AccuracyPerCameraCsv(runs));
}

bool RunRobustness(const RobustnessOptions& options,
                   const std::string& folder) {
  std::cout << "Robustness (paper Table 3, Fig. 6): " << options.cells.size()
            << " rig/scene/difficulty cells x " << options.num_sequences
            << " sequences of " << options.framesets_per_sequence
            << " framesets x " << options.methods.size() << " methods"
            << std::endl;
  const std::vector<RobustnessCell> cells =
      RunRobustnessExperiment(options, [](const RobustnessCell& cell) {
        std::cout << "  " << cell.spec.Label() << " (" << std::fixed
                  << std::setprecision(0) << cell.wall_seconds << " s):";
        for (const ShortSequenceResult& result : cell.results) {
          std::cout << " " << CalibrationMethodName(result.method) << " "
                    << result.PercentComplete() << "% complete, "
                    << result.PercentGood() << "% good;";
        }
        std::cout << std::endl;
      });
  const std::string paper_table = FormatRobustnessPaperTable(cells);
  std::cout << paper_table << std::endl;
  std::ostringstream markdown;
  markdown << "# Robustness on short sequences (paper Table 3, Fig. 6)\n\n"
           << options.num_sequences << " random sequences of "
           << options.framesets_per_sequence << " framesets per cell, cut "
           << "from a " << options.recording_framesets
           << "-frameset recording. Complete: every camera calibrated. "
              "Good: complete, every camera's rotation error < 1 deg and "
              "center error < 1 cm (indoor) / 2 cm (outdoor).\n\n";
  for (const BenchmarkDifficulty& difficulty : BenchmarkDifficulties()) {
    markdown << "- **" << difficulty.name << "**: " << difficulty.description
             << "\n";
  }
  markdown << "\n## Complete and good calibrations (%)\n\n"
           << paper_table << "\n![good calibrations](robustness_good.svg)\n\n"
           << "## Errors before the final bundle adjustment (Fig. 6)\n\n"
              "Cumulative distributions over every camera of every sequence "
              "(failed sequences count as never reaching an error): "
              "`plots/initial_<cell>_{rotation,translation}.svg`, and the "
              "same after the final bundle adjustment: "
              "`plots/final_<cell>_*.svg`.\n\n";
  for (const RobustnessCell& cell : cells) {
    markdown << "- " << cell.spec.Label() << ": [rotation](plots/initial_"
             << cell.spec.Key()
             << "_rotation.svg), [translation](plots/initial_"
             << cell.spec.Key() << "_translation.svg)\n";
  }
  markdown << "\n## Details per cell\n\n" << FormatRobustnessDetails(cells);
  const std::string plots =
      (boost::filesystem::path(folder) / "plots").string();
  boost::system::error_code error_code;
  boost::filesystem::create_directories(plots, error_code);
  if (error_code) {
    PrintError("cannot create " + plots + ": " + error_code.message());
    return false;
  }
  for (const RobustnessCell& cell : cells) {
    for (const bool final_errors : {false, true}) {
      for (const bool rotation : {true, false}) {
        const std::string name =
            std::string(final_errors ? "final_" : "initial_") +
            cell.spec.Key() + (rotation ? "_rotation.svg" : "_translation.svg");
        if (!WriteResult(plots, name,
                         ErrorDistributionSvg(cell, rotation, final_errors))) {
          return false;
        }
      }
    }
  }
  return WriteResult(folder, "robustness.md", markdown.str()) &&
         WriteResult(folder, "robustness.csv", RobustnessCsv(cells)) &&
         WriteResult(folder, "robustness_good.svg", GoodCalibrationsSvg(cells));
}

struct BenchmarkCommandOptions {
  std::string experiment = "short_sequence";
  std::string preset = "ring5";
  std::string scene_name = "indoor";
  std::string difficulty_name = "easy";
  std::string output_path;
  bool quick = false;
  int seed = 0;
  int num_threads = -1;
  int num_sequences = 100;
  int framesets_per_sequence = 10;
  int recording_framesets = 120;
  int accuracy_framesets = 60;
  // Comma-separated method names; empty: the paper's methods of each table
  // (paper_methods.h).
  std::string methods;
  DataOverrides overrides;
};

// --methods into `methods`; left unchanged (the table's default) if empty.
bool ParseMethods(const std::string& names,
                  std::vector<CalibrationMethod>* methods) {
  if (names.empty()) return true;
  methods->clear();
  for (const std::string& name : colmap::CSVToVector<std::string>(names)) {
    CalibrationMethod method;
    if (!CalibrationMethodFromName(name, &method)) {
      PrintError("unknown method " + name +
                 " in --methods (known, "
                 "known_refine, known_ra, rd, rd_ra, 1dr)");
      return false;
    }
    methods->push_back(method);
  }
  return !methods->empty();
}

boost::program_options::options_description Describe(
    BenchmarkCommandOptions* o) {
  boost::program_options::options_description description =
      CommandOptions("rig_calibrator_lab benchmark options");
  AddOption(&description, "experiment", &o->experiment,
            "short_sequence (one robustness table), accuracy, robustness or "
            "all");
  AddUnsetOption(&description, "output_path", &o->output_path,
                 "short_sequence: also write the table (Markdown) to this "
                 "file; accuracy/robustness/all: the results folder "
                 "(required)");
  AddOption(&description, "quick", &o->quick,
            "1: a fast smoke run (fewer framesets, sequences, scenes)");
  AddOption(&description, "preset", &o->preset,
            "short_sequence: ring5, fisheye_helmet5, car_surround4 or "
            "stereo_pair");
  AddOption(&description, "scene", &o->scene_name,
            "short_sequence: indoor or outdoor");
  AddOption(&description, "difficulty", &o->difficulty_name,
            "short_sequence: easy or hard (the data below override it)");
  AddOption(&description, "num_sequences", &o->num_sequences,
            "short sequences per cell (paper §5.3)");
  AddOption(&description, "framesets_per_sequence", &o->framesets_per_sequence,
            "framesets per sequence");
  AddOption(&description, "recording_framesets", &o->recording_framesets,
            "framesets of the recording the sequences are cut from");
  AddOption(&description, "accuracy_framesets", &o->accuracy_framesets,
            "framesets of each accuracy recording");
  AddUnsetOption(&description, "methods", &o->methods,
                 "comma-separated methods, e.g. known,known_refine,known_ra "
                 "(default: the paper's; Table 1: known, known_refine, rd, "
                 "rd_ra, 1dr; Table 3 and short_sequence: rd, rd_ra, 1dr)");
  o->overrides.AddOptions(&description);
  AddOption(&description, "num_threads", &o->num_threads,
            "calibrations run in parallel (-1: all cores)");
  AddOption(&description, "seed", &o->seed, "random seed");
  return description;
}

int RunShortSequence(const BenchmarkCommandOptions& command) {
  ShortSequenceOptions options;
  BenchmarkScene scene;
  BenchmarkDifficulty difficulty;
  if (!RigPresetFromName(command.preset, &options.recording.preset) ||
      !BenchmarkSceneFromName(command.scene_name, &scene) ||
      !BenchmarkDifficultyFromName(command.difficulty_name, &difficulty)) {
    return PrintError("unknown preset, scene or difficulty: " + command.preset +
                      ", " + command.scene_name + ", " +
                      command.difficulty_name);
  }
  if (!ParseMethods(command.methods, &options.methods)) return EXIT_FAILURE;
  command.overrides.Apply(&difficulty);
  ApplyScene(scene, &options.recording);
  ApplyDifficulty(difficulty, &options);
  options.recording.num_framesets = command.recording_framesets;
  options.recording.seed = static_cast<unsigned int>(command.seed);
  options.num_sequences = command.num_sequences;
  options.framesets_per_sequence = command.framesets_per_sequence;
  options.good_center_error = scene.good_center_error;
  options.seed = static_cast<unsigned int>(command.seed);
  options.num_threads = command.num_threads;
  std::string error;
  if (!options.recording.Check(&error)) return PrintError(error);
  std::cout << "Short-sequence robustness, " << command.preset << " / "
            << scene.name << ": " << options.num_sequences << " sequences of "
            << options.framesets_per_sequence << " framesets; "
            << options.recording.points_per_image
            << " correspondences per image, window "
            << options.recording.feature_window << ", noise "
            << options.recording.noise_px << " px, outliers "
            << options.recording.outlier_ratio << ", missing "
            << options.recording.missing_image_ratio << ", stride "
            << options.frameset_stride << std::endl;
  const std::string table =
      FormatShortSequenceResults(RunShortSequenceExperiment(options));
  std::cout << table << std::flush;
  if (!command.output_path.empty() &&
      !WriteFileAtomically(command.output_path, table, &error)) {
    return PrintError(error);
  }
  return EXIT_SUCCESS;
}

// --experiment accuracy, robustness or all.
int RunExperiments(const BenchmarkCommandOptions& command) {
  const std::string& experiment = command.experiment;
  const bool run_accuracy = experiment == "accuracy" || experiment == "all";
  const bool run_robustness = experiment == "robustness" || experiment == "all";
  if (!run_accuracy && !run_robustness) {
    return PrintError("unknown experiment " + experiment +
                      " (short_sequence, accuracy, robustness or all)");
  }
  if (command.output_path.empty()) {
    return PrintError("--experiment " + experiment +
                      " needs --output_path (the results folder)");
  }
  boost::system::error_code error_code;
  boost::filesystem::create_directories(command.output_path, error_code);
  if (error_code) {
    return PrintError("cannot create the results folder " +
                      command.output_path + ": " + error_code.message());
  }
  if (run_accuracy) {
    AccuracyOptions options;
    options.num_framesets = command.quick ? 15 : command.accuracy_framesets;
    if (command.quick) options.scenes.resize(1);
    if (!ParseMethods(command.methods, &options.methods)) return EXIT_FAILURE;
    options.seed = static_cast<unsigned int>(command.seed);
    options.num_threads = command.num_threads;
    if (!RunAccuracy(options, command.output_path)) return EXIT_FAILURE;
  }
  if (run_robustness) {
    RobustnessOptions options;
    options.num_sequences = command.quick ? 6 : command.num_sequences;
    options.framesets_per_sequence = command.framesets_per_sequence;
    options.recording_framesets =
        command.quick ? 40 : command.recording_framesets;
    if (!ParseMethods(command.methods, &options.methods)) return EXIT_FAILURE;
    options.seed = static_cast<unsigned int>(command.seed);
    options.num_threads = command.num_threads;
    if (!RunRobustness(options, command.output_path)) return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace

int RunBenchmark(int argc, char** argv) {
  BenchmarkCommandOptions options;
  if (const std::optional<int> exit_code = ParseCommandLine(
          argc, argv, Describe(&options),
          "rig_calibrator_lab benchmark: the paper's accuracy (§5.2) and "
          "robustness (§5.3, §5.4) experiments on synthetic rigs")) {
    return *exit_code;
  }
  // Hundreds of calibrations: keep their per-stage log lines off the tables.
  FLAGS_minloglevel = google::GLOG_WARNING;
  return options.experiment == "short_sequence" ? RunShortSequence(options)
                                                : RunExperiments(options);
}

}  // namespace rig_calibrator
