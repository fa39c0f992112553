// The last line of defence of the commands: an exception that escapes a
// command is a defect (every input error must be reported by the code that
// finds it, naming the file), but it must still end the run with a message
// and an exit code, not with std::terminate's abort.
#pragma once

#include <functional>

namespace rig_calibrator {

// Runs `command` and returns its exit code. An exception that escapes it is
// printed as one line, "ERROR: internal error: <what> (...)", on stderr and
// gives EXIT_FAILURE. The commands write their output folders atomically
// (atomic_output.h removes the temporary folder when an exception passes),
// so nothing of the run is left behind.
int RunGuarded(const std::function<int()>& command);

}  // namespace rig_calibrator
