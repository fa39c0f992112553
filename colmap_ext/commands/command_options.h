// Colmap-style command-line parsing shared by the sub-commands:
// `--name value`, options grouped as `--Group.name`, `-h/--help`; and the
// option declarations more than one sub-command has.
#pragma once

#include <boost/program_options.hpp>
#include <optional>
#include <string>

#include "colmap_ext/io/error_output.h"

namespace rig_calibrator {

// Options of a sub-command, with `-h/--help` already declared.
boost::program_options::options_description CommandOptions(
    const std::string& caption);

// `--name value` bound to *value; the help shows *value as the default.
template <typename T>
void AddOption(boost::program_options::options_description* description,
               const std::string& name, T* value, const std::string& help) {
  description->add_options()(
      name.c_str(), boost::program_options::value(value)->default_value(*value),
      help.c_str());
}

// `--name value` bound to *value, without a default in the help (*value is
// left alone when the option is not given).
template <typename T>
void AddUnsetOption(boost::program_options::options_description* description,
                    const std::string& name, T* value,
                    const std::string& help) {
  description->add_options()(name.c_str(), boost::program_options::value(value),
                             help.c_str());
}

// `--name value` that must be given.
template <typename T>
void AddRequiredOption(boost::program_options::options_description* description,
                       const std::string& name, T* value,
                       const std::string& help) {
  description->add_options()(name.c_str(),
                             boost::program_options::value(value)->required(),
                             help.c_str());
}

// --overwrite: replace a non-empty output folder.
void AddOverwriteOption(
    boost::program_options::options_description* description, bool* overwrite);

// Parses argv into the variables bound in `description`. Returns nothing if
// the command should run, else its exit code after printing the help (`-h`,
// `--help`: success; `title` above the options) or a parse error naming the
// option (failure).
std::optional<int> ParseCommandLine(
    int argc, char** argv,
    const boost::program_options::options_description& description,
    const std::string& title);

}  // namespace rig_calibrator
