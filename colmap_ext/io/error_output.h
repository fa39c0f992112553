// How the commands report an error on the terminal.
#pragma once

#include <string>

namespace rig_calibrator {

// Prints "ERROR: <message>" to stderr; returns EXIT_FAILURE, the exit code
// of a command that stops on it.
int PrintError(const std::string& message);

}  // namespace rig_calibrator
