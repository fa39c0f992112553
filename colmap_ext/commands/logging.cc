#include <colmap/util/logging.h>

#include "colmap_ext/commands/commands.h"

namespace rig_calibrator {

void InitializeLogging(char** argv) {
  colmap::InitializeGlog(argv);
  // Messages go to the terminal, not to log files in /tmp.
  FLAGS_logtostderr = true;
}

}  // namespace rig_calibrator
