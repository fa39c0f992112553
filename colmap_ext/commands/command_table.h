// A command made of sub-commands behind one name (`PROGRAM <command>
// [options]`): the help that lists them and the dispatch to them. The
// shipped `rig_calibrator` (rig_calibrator_command.h) and the lab's
// `rig_calibrator_lab` (colmap_ext/lab_commands/lab_commands.h) are two
// tables of it.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace rig_calibrator {

// One sub-command: it takes (argc, argv) with argv[0] the program name and
// returns the process exit code.
struct SubCommand {
  std::string name;
  std::function<int(int, char**)> run;
  std::string summary;  // one line of the help
};

struct CommandTable {
  std::string title;  // the help's first line
  std::vector<SubCommand> commands;
  // The sub-command that a first argument starting with '-' goes to (so
  // that `PROGRAM -h` shows its options), and the usage line of running it
  // without its name; empty: a command name is required.
  std::string default_command;
  std::string default_usage;
};

// Runs `PROGRAM <command> [options]` with argv[0] the program name: no
// argument, `help` or `commands` lists the sub-commands. `program` is how
// the user invoked the command (e.g. "rig_calibrator" or "colmap
// rig_calibrator"), used in the usage and error messages. Returns the exit
// code; an exception that escapes a sub-command ends it with a one-line
// error and EXIT_FAILURE (RunGuarded).
int RunCommandTable(const CommandTable& table, const std::string& program,
                    int argc, char** argv);

}  // namespace rig_calibrator
