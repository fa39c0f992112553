// The time a pipeline stage took (pipeline_report.h's StageTimer measures
// it; timings.json reports it).
#pragma once

#include <string>

namespace rig_calibrator {

struct StageTiming {
  std::string stage;
  double seconds = 0;  // wall time
  // CPU time of the whole process (all threads, user + system) during the
  // stage: unlike wall time, hardly affected by other work on the machine.
  double cpu_seconds = 0;
  // Solver iterations of the stage's bundle adjustment (Ceres steps over
  // all its solves); 0 for stages without one.
  int num_iterations = 0;
};

}  // namespace rig_calibrator
