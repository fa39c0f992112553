#include "colmap_ext/commands/command_options.h"

#include <cstdlib>
#include <iostream>

namespace rig_calibrator {

bool ParseCommandLine(
    int argc, char** argv,
    const boost::program_options::options_description& description,
    const std::string& title, int* exit_code) {
  namespace po = boost::program_options;
  po::variables_map values;
  try {
    po::store(po::parse_command_line(argc, argv, description), values);
    if (values.count("help")) {
      std::cout << title << "\n\n" << description << std::endl;
      *exit_code = EXIT_SUCCESS;
      return false;
    }
    po::notify(values);
  } catch (const std::exception& exception) {
    std::cerr << "ERROR: " << exception.what()
              << " (run with --help for the options)" << std::endl;
    *exit_code = EXIT_FAILURE;
    return false;
  }
  return true;
}

}  // namespace rig_calibrator
