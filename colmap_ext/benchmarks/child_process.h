// Measuring a computation in a child process of its own, so that its peak
// memory (wait4's ru_maxrss) is its own and not that of earlier runs.
#pragma once

#include <string>
#include <vector>

namespace rig_calibrator {

// User + system CPU seconds of this process so far, over all threads.
double ProcessCpuSeconds();

struct ChildOutcome {
  bool ok = false;          // exited with status 0
  std::string result_text;  // the contents of the result file
  double peak_memory_mb = 0;
  // From fork to wait4's return, and the child's user + system CPU (all its
  // threads, wait4's rusage).
  double wall_seconds = 0, cpu_seconds = 0;
  std::string error;
};

// Runs `executable` (by default this one, /proc/self/exe) with `arguments`
// (argv, argv[0] first), waits for it and reads the file it wrote to
// `result_path`.
ChildOutcome RunChildProcess(const std::vector<std::string>& arguments,
                             const std::string& result_path,
                             const std::string& executable = "/proc/self/exe");

// "N cores online; load average a, b, c (1, 5, 15 min)": what else ran on
// the machine.
std::string MachineDescription();

}  // namespace rig_calibrator
