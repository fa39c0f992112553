#include "src/experiments/robustness_experiment.h"

#include <colmap/util/timer.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace rig_calibrator {
namespace {

std::string Percent(double value) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << value;
  return text.str();
}

std::string Method(const ShortSequenceResult& result) {
  return CalibrationMethodName(result.method);
}

}  // namespace

std::string RobustnessCellSpec::Label() const {
  return RigPresetName(preset) + " / " + scene.name + " / " + difficulty.name;
}

std::string RobustnessCellSpec::Key() const {
  return RigPresetName(preset) + "_" + scene.name + "_" + difficulty.name;
}

std::vector<RobustnessCellSpec> DefaultRobustnessCells() {
  BenchmarkScene indoor, outdoor;
  BenchmarkSceneFromName("indoor", &indoor);
  BenchmarkSceneFromName("outdoor", &outdoor);
  const std::vector<std::pair<RigPreset, BenchmarkScene>> rigs = {
      {RigPreset::kFisheyeHelmet5, indoor},
      {RigPreset::kFisheyeHelmet5, outdoor},
      {RigPreset::kRing5, indoor},
      {RigPreset::kRing5, outdoor},
      {RigPreset::kCarSurround4, outdoor},
      {RigPreset::kStereoPair, indoor}};
  std::vector<RobustnessCellSpec> cells;
  for (const BenchmarkDifficulty& difficulty : BenchmarkDifficulties()) {
    for (const auto& [preset, scene] : rigs) {
      cells.push_back({preset, scene, difficulty});
    }
  }
  return cells;
}

std::vector<RobustnessCell> RunRobustnessExperiment(
    const RobustnessOptions& options,
    const std::function<void(const RobustnessCell&)>& progress) {
  std::vector<RobustnessCell> cells;
  for (const RobustnessCellSpec& spec : options.cells) {
    ShortSequenceOptions sequence_options;
    sequence_options.recording.preset = spec.preset;
    sequence_options.recording.num_framesets = options.recording_framesets;
    sequence_options.recording.seed = options.seed;
    ApplyScene(spec.scene, &sequence_options.recording);
    ApplyDifficulty(spec.difficulty, &sequence_options);
    sequence_options.num_sequences = options.num_sequences;
    sequence_options.framesets_per_sequence = options.framesets_per_sequence;
    sequence_options.good_center_error = spec.scene.good_center_error;
    sequence_options.methods = options.methods;
    sequence_options.seed = options.seed;
    sequence_options.num_threads = options.num_threads;
    RobustnessCell cell;
    cell.spec = spec;
    colmap::Timer timer;
    timer.Start();
    cell.results = RunShortSequenceExperiment(sequence_options);
    cell.wall_seconds = timer.ElapsedSeconds();
    if (progress) progress(cell);
    cells.push_back(std::move(cell));
  }
  return cells;
}

std::string FormatRobustnessPaperTable(
    const std::vector<RobustnessCell>& cells) {
  std::ostringstream table;
  if (cells.empty()) return "";
  table << "| rig / scene / difficulty | |";
  for (const ShortSequenceResult& result : cells[0].results) {
    table << " " << Method(result) << " |";
  }
  table << "\n|---|---|";
  for (size_t m = 0; m < cells[0].results.size(); ++m) table << "---|";
  table << "\n";
  for (const RobustnessCell& cell : cells) {
    // The best method of each line in bold, as in the paper.
    for (const bool good : {false, true}) {
      double best = 0;
      for (const ShortSequenceResult& result : cell.results) {
        best = std::max(best,
                        good ? result.PercentGood() : result.PercentComplete());
      }
      table << "| " << (good ? "" : "**" + cell.spec.Label() + "**") << " | "
            << (good ? "good" : "complete") << " |";
      for (const ShortSequenceResult& result : cell.results) {
        const double value =
            good ? result.PercentGood() : result.PercentComplete();
        const bool bold = value == best && best > 0;
        table << " " << (bold ? "**" : "") << Percent(value)
              << (bold ? "**" : "") << " |";
      }
      table << "\n";
    }
  }
  return table.str();
}

std::string FormatRobustnessDetails(const std::vector<RobustnessCell>& cells) {
  std::ostringstream text;
  for (const RobustnessCell& cell : cells) {
    text << "#### " << cell.spec.Label() << "\n\n"
         << "Good: rotation < 1 deg and center < "
         << 100 * cell.spec.scene.good_center_error << " cm. "
         << cell.spec.difficulty.description << ". Wall time " << std::fixed
         << std::setprecision(0) << cell.wall_seconds << " s.\n\n"
         << FormatShortSequenceResults(cell.results) << "\n";
  }
  return text.str();
}

std::string RobustnessCsv(const std::vector<RobustnessCell>& cells) {
  std::ostringstream csv;
  csv << "rig,scene,difficulty,method,sequences,complete_percent,"
         "good_percent,fallbacks,median_max_rotation_deg,"
         "median_max_center_cm,initial_median_rotation_deg,"
         "initial_median_center_cm,seconds_per_sequence\n"
      << std::setprecision(6);
  for (const RobustnessCell& cell : cells) {
    for (const ShortSequenceResult& result : cell.results) {
      csv << RigPresetName(cell.spec.preset) << "," << cell.spec.scene.name
          << "," << cell.spec.difficulty.name << "," << Method(result) << ","
          << result.num_sequences << "," << result.PercentComplete() << ","
          << result.PercentGood() << "," << result.num_fallbacks << ","
          << MedianWithFailures(result.max_rotation_deg) << ","
          << 100 * MedianWithFailures(result.max_center_error) << ","
          << MedianWithFailures(result.initial_rotation_deg) << ","
          << 100 * MedianWithFailures(result.initial_center_error) << ","
          << result.seconds / std::max(1, result.num_sequences) << "\n";
    }
  }
  return csv.str();
}

}  // namespace rig_calibrator
