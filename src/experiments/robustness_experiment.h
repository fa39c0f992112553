// The paper's robustness experiment (§5.3, Table 3) and its evaluation of the
// initial estimates (§5.4, Fig. 6) over rig presets, scenes and difficulties:
// each cell runs the short-sequence experiment
// (src/experiments/short_sequence_experiment.h) and the results become tables
// and CSV (the plots: colmap_ext/lab_commands/robustness_figures.h).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "src/experiments/benchmark_scenarios.h"
#include "src/experiments/short_sequence_experiment.h"

namespace rig_calibrator {

struct RobustnessCellSpec {
  RigPreset preset = RigPreset::kRing5;
  BenchmarkScene scene;
  BenchmarkDifficulty difficulty;

  // "ring5 / indoor / hard"
  std::string Label() const;
  // "ring5_indoor_hard", for file names
  std::string Key() const;
};

// Every preset in its natural scene(s) (the helmet and the ring indoors and
// outdoors, the car outdoors, the stereo pair indoors), each easy and hard.
std::vector<RobustnessCellSpec> DefaultRobustnessCells();

struct RobustnessOptions {
  std::vector<RobustnessCellSpec> cells = DefaultRobustnessCells();
  int num_sequences = 100;
  int framesets_per_sequence = 10;
  int recording_framesets = 120;
  std::vector<CalibrationMethod> methods = RobustnessTableMethods();
  unsigned int seed = 0;
  int num_threads = -1;
};

struct RobustnessCell {
  RobustnessCellSpec spec;
  std::vector<ShortSequenceResult> results;  // one per method
  double wall_seconds = 0;
};

// Calls `progress` (may be empty) after each cell. Deterministic for a seed.
std::vector<RobustnessCell> RunRobustnessExperiment(
    const RobustnessOptions& options,
    const std::function<void(const RobustnessCell&)>& progress = {});

// The paper's Table 3 layout: per cell a "complete" and a "good" line (%),
// one column per method.
std::string FormatRobustnessPaperTable(
    const std::vector<RobustnessCell>& cells);

// Per cell the detailed short-sequence table (median errors, initial errors,
// time).
std::string FormatRobustnessDetails(const std::vector<RobustnessCell>& cells);

// One row per cell and method.
std::string RobustnessCsv(const std::vector<RobustnessCell>& cells);

}  // namespace rig_calibrator
