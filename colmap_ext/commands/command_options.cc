#include "colmap_ext/commands/command_options.h"

#include <cstdlib>
#include <iostream>

namespace rig_calibrator {

namespace po = boost::program_options;

po::options_description CommandOptions(const std::string& caption) {
  po::options_description description(caption);
  description.add_options()("help,h", "show this help");
  return description;
}

void AddOverwriteOption(po::options_description* description, bool* overwrite) {
  AddOption(description, "overwrite", overwrite,
            "replace a non-empty output folder");
}

void AddSyntheticDataOptions(po::options_description* description,
                             SyntheticRigOptions* options) {
  AddOption(description, "points_per_image", &options->points_per_image,
            "correspondences per image");
  AddOption(description, "noise_px", &options->noise_px,
            "pixel noise (standard deviation)");
  AddOption(description, "outlier_ratio", &options->outlier_ratio,
            "share of wrong 2D-3D matches");
  AddOption(description, "missing_image_ratio", &options->missing_image_ratio,
            "share of images dropped");
}

std::optional<int> ParseCommandLine(int argc, char** argv,
                                    const po::options_description& description,
                                    const std::string& title) {
  po::variables_map values;
  try {
    po::store(po::parse_command_line(argc, argv, description), values);
    if (values.count("help")) {
      std::cout << title << "\n\n" << description << std::endl;
      return EXIT_SUCCESS;
    }
    po::notify(values);
  } catch (const std::exception& exception) {
    return PrintError(std::string(exception.what()) +
                      " (run with --help for the options)");
  }
  return std::nullopt;
}

}  // namespace rig_calibrator
