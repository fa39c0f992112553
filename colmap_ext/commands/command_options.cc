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
