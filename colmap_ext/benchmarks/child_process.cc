#include "colmap_ext/benchmarks/child_process.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace rig_calibrator {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace

double ProcessCpuSeconds() {
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

ChildOutcome RunChildProcess(const std::vector<std::string>& arguments,
                             const std::string& result_path,
                             const std::string& executable) {
  ChildOutcome outcome;
  std::vector<char*> child_argv;
  for (const std::string& argument : arguments) {
    child_argv.push_back(const_cast<char*>(argument.c_str()));
  }
  child_argv.push_back(nullptr);
  std::cout.flush();
  const auto start_time = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) {
    outcome.error = "fork failed";
    return outcome;
  }
  if (pid == 0) {
    execv(executable.c_str(), child_argv.data());
    std::perror(("execv " + executable).c_str());
    _exit(127);
  }
  int status = 0;
  rusage usage;
  if (wait4(pid, &status, 0, &usage) != pid) {
    outcome.error = "wait4 failed";
    return outcome;
  }
  outcome.wall_seconds = std::chrono::duration<double>(
                             std::chrono::steady_clock::now() - start_time)
                             .count();
  outcome.cpu_seconds =
      usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
      1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  // Linux reports ru_maxrss in kilobytes.
  outcome.peak_memory_mb = usage.ru_maxrss / 1024.0;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    outcome.error = WIFSIGNALED(status)
                        ? "the measurement was killed by signal " +
                              std::to_string(WTERMSIG(status))
                        : "the measurement exited with status " +
                              std::to_string(WEXITSTATUS(status));
    return outcome;
  }
  outcome.result_text = ReadText(result_path);
  outcome.ok = true;
  return outcome;
}

std::string MachineDescription() {
  std::ostringstream text;
  double load[3] = {0, 0, 0};
  getloadavg(load, 3);
  text << sysconf(_SC_NPROCESSORS_ONLN) << " cores online; load average "
       << std::fixed << std::setprecision(2) << load[0] << ", " << load[1]
       << ", " << load[2] << " (1, 5, 15 min)";
  return text.str();
}

}  // namespace rig_calibrator
