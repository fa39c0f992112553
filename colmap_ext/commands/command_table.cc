#include "colmap_ext/commands/command_table.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>

#include "colmap_ext/commands/commands.h"
#include "colmap_ext/commands/guarded_run.h"

namespace rig_calibrator {
namespace {

int ShowHelp(const CommandTable& table, const std::string& program) {
  std::cout << table.title << "\n\nUsage:\n";
  if (!table.default_command.empty()) {
    std::cout << "  " << program << " [" << table.default_command << "] "
              << table.default_usage << "\n";
  }
  std::cout << "  " << program << " <command> [options]\n"
            << "  " << program << " <command> --help\n\n"
            << "Commands:\n";
  for (const SubCommand& command : table.commands) {
    std::cout << "  " << command.name
              << std::string(std::max<int>(1, 19 - command.name.size()), ' ')
              << command.summary << "\n";
  }
  return EXIT_SUCCESS;
}

const SubCommand* FindCommand(const CommandTable& table,
                              const std::string& name) {
  for (const SubCommand& command : table.commands) {
    if (command.name == name) return &command;
  }
  return nullptr;
}

int DispatchCommand(const CommandTable& table, const std::string& program,
                    int argc, char** argv) {
  if (argc == 1) return ShowHelp(table, program);
  const std::string first = argv[1];
  if (first == "help" || first == "commands") return ShowHelp(table, program);
  if (!first.empty() && first[0] == '-' && !table.default_command.empty()) {
    return FindCommand(table, table.default_command)->run(argc, argv);
  }
  if (const SubCommand* command = FindCommand(table, first)) {
    argv[1] = argv[0];
    return command->run(argc - 1, argv + 1);
  }
  std::cerr << "ERROR: unknown command `" << first << "`; run `" << program
            << " help` for the list." << std::endl;
  return EXIT_FAILURE;
}

}  // namespace

int RunCommandTable(const CommandTable& table, const std::string& program,
                    int argc, char** argv) {
  InitializeLogging(argv);
  return RunGuarded(
      [&] { return DispatchCommand(table, program, argc, argv); });
}

}  // namespace rig_calibrator
