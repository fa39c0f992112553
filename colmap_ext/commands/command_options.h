// Colmap-style command-line parsing shared by the sub-commands:
// `--name value`, options grouped as `--Group.name`, `-h/--help`.
#pragma once

#include <boost/program_options.hpp>
#include <string>

namespace rig_calibrator {

// Parses argv into the variables bound in `description`. Returns true if the
// command should run. Returns false, with *exit_code set, after printing the
// help (`-h`, `--help`: success) or a parse error naming the option
// (failure).
bool ParseCommandLine(
    int argc, char** argv,
    const boost::program_options::options_description& description,
    const std::string& title, int* exit_code);

}  // namespace rig_calibrator
