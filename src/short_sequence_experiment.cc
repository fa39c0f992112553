#include "src/short_sequence_experiment.h"

#include <colmap/util/timer.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>

#include "src/evaluation.h"

namespace rig_calibrator {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

}  // namespace

double ShortSequenceResult::PercentComplete() const {
  return num_sequences ? 100.0 * num_complete / num_sequences : 0;
}

double ShortSequenceResult::PercentGood() const {
  return num_sequences ? 100.0 * num_good / num_sequences : 0;
}

std::vector<ShortSequenceResult> RunShortSequenceExperiment(
    const ShortSequenceOptions& options) {
  const SyntheticRig recording = GenerateSyntheticRig(options.recording);
  const int span =
      (options.framesets_per_sequence - 1) * options.frameset_stride + 1;
  const int num_starts = std::max(
      1, static_cast<int>(recording.dataset.frameset_names.size()) - span + 1);
  std::mt19937 random(options.seed);
  std::uniform_int_distribution<int> start_distribution(0, num_starts - 1);
  std::vector<std::vector<int>> sequences(options.num_sequences);
  for (std::vector<int>& sequence : sequences) {
    const int start = start_distribution(random);
    for (int k = 0; k < options.framesets_per_sequence; ++k) {
      sequence.push_back(start + k * options.frameset_stride);
    }
  }

  std::vector<ShortSequenceResult> results;
  for (const CalibrationMethod method : options.methods) {
    ShortSequenceResult result;
    result.method = method;
    colmap::Timer timer;
    timer.Start();
    for (size_t s = 0; s < sequences.size(); ++s) {
      const SyntheticRig rig = SelectFramesets(recording, sequences[s]);
      PipelineOptions pipeline;
      pipeline.method = method;
      pipeline.print_progress = false;
      pipeline.num_threads = options.num_threads;
      pipeline.seed = options.seed + static_cast<unsigned int>(s);
      RigCalibration calibration;
      PipelineReport report;
      ++result.num_sequences;
      const bool complete =
          CalibrateRig(pipeline, rig.dataset, &calibration, &report) &&
          std::all_of(calibration.camera_calibrated.begin(),
                      calibration.camera_calibrated.end(),
                      [](bool calibrated) { return calibrated; });
      if (!complete) {
        result.max_rotation_deg.push_back(
            std::numeric_limits<double>::infinity());
        result.max_center_error.push_back(
            std::numeric_limits<double>::infinity());
        continue;
      }
      ++result.num_complete;
      const CalibrationError error = CompareCalibrations(
          rig.truth.cameras, rig.truth.cam_from_rig, calibration.cameras,
          calibration.cam_from_rig, /*align_scale=*/false);
      result.max_rotation_deg.push_back(error.MaxRotationDeg());
      result.max_center_error.push_back(error.MaxCenterError());
      if (error.MaxRotationDeg() < options.good_rotation_deg &&
          error.MaxCenterError() < options.good_center_error) {
        ++result.num_good;
      }
    }
    result.seconds = timer.ElapsedSeconds();
    results.push_back(result);
  }
  return results;
}

std::string FormatShortSequenceResults(
    const std::vector<ShortSequenceResult>& results) {
  std::ostringstream table;
  table << "| method | sequences | complete | good | median max rotation error "
           "(deg) | median max center error (cm) | seconds per sequence |\n"
           "|---|---|---|---|---|---|---|\n";
  for (const ShortSequenceResult& result : results) {
    table << "| " << CalibrationMethodName(result.method) << " | "
          << result.num_sequences << " | " << std::fixed << std::setprecision(0)
          << result.PercentComplete() << "% | " << result.PercentGood()
          << "% | " << std::setprecision(3) << Median(result.max_rotation_deg)
          << " | " << std::setprecision(2)
          << 100.0 * Median(result.max_center_error) << " | "
          << result.seconds / std::max(1, result.num_sequences) << " |\n";
  }
  return table.str();
}

}  // namespace rig_calibrator
