// colmap: COLMAP 3.8's command line plus `colmap rig_calibrator`.
//
//   colmap feature_extractor | mapper | ... [options]   COLMAP's own commands
//   colmap rig_calibrator [calibrate|evaluate|...] ...   rig_calibrator's
//   colmap help                                          both lists
//
// COLMAP's commands are COLMAP's own command table: its src/exe/colmap.cc as
// COLMAP's build compiled it, with its `main` renamed ColmapMain
// (scripts/setup_deps.sh, colmap_ext/CMakeLists.txt). Only `rig_calibrator` and the help are
// handled here; everything else, unknown commands included, goes to
// ColmapMain unchanged.
#include <iostream>
#include <sstream>
#include <string>

#include "colmap_ext/commands/colmap_help.h"
#include "colmap_ext/commands/rig_calibrator_command.h"

// COLMAP's main (src/exe/colmap.cc), renamed by objcopy: like `main`, its
// symbol is the plain name, not a C++ mangled one.
extern "C" int ColmapMain(int argc, char** argv);

int main(int argc, char** argv) {
  const std::string command = argc > 1 ? argv[1] : "";
  if (command == "rig_calibrator") {
    argv[1] = argv[0];
    return rig_calibrator::RunRigCalibrator("colmap rig_calibrator", argc - 1,
                                            argv + 1);
  }
  if (argc > 1 && command != "help" && command != "-h" && command != "--help") {
    return ColmapMain(argc, argv);
  }
  // COLMAP prints its help to std::cout; it is captured and extended.
  std::ostringstream colmap_help;
  std::streambuf* const cout_buffer = std::cout.rdbuf(colmap_help.rdbuf());
  const int status = ColmapMain(argc, argv);
  std::cout.rdbuf(cout_buffer);
  std::cout << rig_calibrator::ExtendColmapHelp(colmap_help.str())
            << std::flush;
  return status;
}
