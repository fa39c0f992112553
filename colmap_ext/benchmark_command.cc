// `rig_calibrator benchmark`: the paper's experiments on synthetic rigs.
// Writes Markdown tables to the terminal and, with --output_path, to a file.
#include <glog/logging.h>

#include <boost/program_options.hpp>
#include <iostream>

#include "colmap_ext/atomic_output.h"
#include "colmap_ext/command_options.h"
#include "colmap_ext/commands.h"
#include "src/short_sequence_experiment.h"

namespace rig_calibrator {

int RunBenchmark(int argc, char** argv) {
  ShortSequenceOptions options;
  std::string preset = "ring5";
  std::string output_path;
  int seed = 0;
  namespace po = boost::program_options;
  po::options_description description("rig_calibrator benchmark options");
  description.add_options()("help,h", "show this help")(
      "preset", po::value(&preset)->default_value(preset),
      "ring5, fisheye_helmet5, car_surround4 or stereo_pair")(
      "num_sequences",
      po::value(&options.num_sequences)->default_value(options.num_sequences),
      "short sequences (paper §5.3)")(
      "framesets_per_sequence",
      po::value(&options.framesets_per_sequence)
          ->default_value(options.framesets_per_sequence),
      "framesets per sequence")(
      "recording_framesets",
      po::value(&options.recording.num_framesets)->default_value(120),
      "framesets of the recording the sequences are cut from")(
      "outlier_ratio",
      po::value(&options.recording.outlier_ratio)
          ->default_value(options.recording.outlier_ratio),
      "share of wrong 2D-3D matches")(
      "missing_image_ratio",
      po::value(&options.recording.missing_image_ratio)
          ->default_value(options.recording.missing_image_ratio),
      "share of images dropped")("seed", po::value(&seed)->default_value(seed),
                                 "random seed")(
      "output_path", po::value(&output_path),
      "also write the table (Markdown) to this file");
  int exit_code = EXIT_SUCCESS;
  if (!ParseCommandLine(argc, argv, description,
                        "rig_calibrator benchmark: robustness of the methods "
                        "on short sequences (paper §5.3, Table 3)",
                        &exit_code)) {
    return exit_code;
  }
  if (!RigPresetFromName(preset, &options.recording.preset)) {
    std::cerr << "ERROR: unknown preset " << preset << std::endl;
    return EXIT_FAILURE;
  }
  // Hundreds of calibrations: keep their per-stage log lines off the table.
  FLAGS_minloglevel = google::GLOG_WARNING;
  options.seed = static_cast<unsigned int>(seed);
  options.recording.seed = static_cast<unsigned int>(seed);
  std::string error;
  if (!options.recording.Check(&error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
  }
  std::cout << "Short-sequence robustness, preset " << preset << ": "
            << options.num_sequences << " sequences of "
            << options.framesets_per_sequence << " framesets" << std::endl;
  const std::vector<ShortSequenceResult> results =
      RunShortSequenceExperiment(options);
  const std::string table = FormatShortSequenceResults(results);
  std::cout << table << std::flush;
  if (!output_path.empty() &&
      !WriteFileAtomically(output_path, table, &error)) {
    std::cerr << "ERROR: " << error << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

}  // namespace rig_calibrator
