#include "colmap_ext/io/error_output.h"

#include <cstdlib>
#include <iostream>

namespace rig_calibrator {

int PrintError(const std::string& message) {
  std::cerr << "ERROR: " << message << std::endl;
  return EXIT_FAILURE;
}

}  // namespace rig_calibrator
