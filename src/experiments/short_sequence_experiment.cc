#include "src/experiments/short_sequence_experiment.h"

#include <colmap/util/math.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>

#include "src/evaluation/evaluation.h"
#include "src/experiments/experiment_calibration.h"

namespace rig_calibrator {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// What one calibration of one sequence gave.
struct SequenceOutcome {
  bool complete = false;
  bool fell_back = false;
  double max_rotation_deg = kInfinity, max_center_error = kInfinity;
  std::vector<double> initial_rotation_deg, initial_center_error;
  std::vector<double> final_rotation_deg, final_center_error;
  double seconds = 0;
};

// Per camera errors of (cameras, cam_from_rig) against the truth; infinity
// for cameras not calibrated, and for all when nothing could be compared.
void PerCameraErrors(const RigGroundTruth& truth,
                     const std::vector<colmap::Camera>& cameras,
                     const std::vector<Rigid3d>& cam_from_rig,
                     const std::vector<bool>& calibrated,
                     std::vector<double>* rotation_deg,
                     std::vector<double>* center_error) {
  const size_t num_cameras = truth.cameras.size();
  rotation_deg->assign(num_cameras, kInfinity);
  center_error->assign(num_cameras, kInfinity);
  if (cameras.size() != num_cameras || cam_from_rig.size() != num_cameras ||
      calibrated.size() != num_cameras) {
    return;
  }
  const CalibrationError error =
      CompareCalibrations(truth.cameras, truth.cam_from_rig, cameras,
                          cam_from_rig, /*align_scale=*/false);
  if (!error.ok()) return;
  for (size_t c = 0; c < num_cameras; ++c) {
    if (!calibrated[c]) continue;
    (*rotation_deg)[c] = error.cameras[c].rotation_deg;
    (*center_error)[c] = error.cameras[c].center_error;
  }
}

SequenceOutcome CalibrateSequence(CalibrationMethod method,
                                  const SyntheticRig& rig, unsigned int seed) {
  SequenceOutcome outcome;
  const size_t num_cameras = rig.truth.cameras.size();
  outcome.initial_rotation_deg.assign(num_cameras, kInfinity);
  outcome.initial_center_error.assign(num_cameras, kInfinity);
  outcome.final_rotation_deg.assign(num_cameras, kInfinity);
  outcome.final_center_error.assign(num_cameras, kInfinity);
  const ExperimentCalibration result = CalibrateSyntheticRig(rig, method, seed);
  const bool success = result.success;
  const RigCalibration& calibration = result.calibration;
  const PipelineReport& report = result.report;
  outcome.seconds = report.total_seconds;
  outcome.fell_back = report.used_method != report.requested_method;
  if (!report.initial_cam_from_rig.empty()) {
    PerCameraErrors(
        rig.truth, report.initial_cameras, report.initial_cam_from_rig,
        report.initial_camera_calibrated, &outcome.initial_rotation_deg,
        &outcome.initial_center_error);
  }
  outcome.complete =
      success && std::all_of(calibration.camera_calibrated.begin(),
                             calibration.camera_calibrated.end(),
                             [](bool calibrated) { return calibrated; });
  if (!success) return outcome;
  PerCameraErrors(rig.truth, calibration.cameras, calibration.cam_from_rig,
                  calibration.camera_calibrated, &outcome.final_rotation_deg,
                  &outcome.final_center_error);
  if (outcome.complete) {
    outcome.max_rotation_deg = *std::max_element(
        outcome.final_rotation_deg.begin(), outcome.final_rotation_deg.end());
    outcome.max_center_error = *std::max_element(
        outcome.final_center_error.begin(), outcome.final_center_error.end());
  }
  return outcome;
}

void Append(const std::vector<double>& values, std::vector<double>* all) {
  all->insert(all->end(), values.begin(), values.end());
}

}  // namespace

double MedianWithFailures(const std::vector<double>& values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  return colmap::Median(values);
}

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
  std::vector<SyntheticRig> rigs(sequences.size());
  for (size_t s = 0; s < sequences.size(); ++s) {
    rigs[s] = SelectFramesets(recording, sequences[s]);
  }
  const int num_threads =
      options.num_threads > 0 ? options.num_threads : omp_get_max_threads();

  std::vector<ShortSequenceResult> results;
  for (const CalibrationMethod method : options.methods) {
    std::vector<SequenceOutcome> outcomes(sequences.size());
#pragma omp parallel for schedule(dynamic) num_threads(num_threads)
    for (int s = 0; s < static_cast<int>(sequences.size()); ++s) {
      outcomes[s] = CalibrateSequence(method, rigs[s],
                                      options.seed + static_cast<unsigned>(s));
    }
    ShortSequenceResult result;
    result.method = method;
    for (const SequenceOutcome& outcome : outcomes) {
      ++result.num_sequences;
      result.seconds += outcome.seconds;
      if (outcome.fell_back) ++result.num_fallbacks;
      result.max_rotation_deg.push_back(outcome.max_rotation_deg);
      result.max_center_error.push_back(outcome.max_center_error);
      Append(outcome.initial_rotation_deg, &result.initial_rotation_deg);
      Append(outcome.initial_center_error, &result.initial_center_error);
      Append(outcome.final_rotation_deg, &result.final_rotation_deg);
      Append(outcome.final_center_error, &result.final_center_error);
      if (!outcome.complete) continue;
      ++result.num_complete;
      if (outcome.max_rotation_deg < options.good_rotation_deg &&
          outcome.max_center_error < options.good_center_error) {
        ++result.num_good;
      }
    }
    results.push_back(std::move(result));
  }
  return results;
}

std::string FormatShortSequenceResults(
    const std::vector<ShortSequenceResult>& results) {
  std::ostringstream table;
  table << "| method | sequences | complete | good | median max rotation error "
           "(deg) | median max center error (cm) | initial median rotation "
           "error (deg) | initial median center error (cm) | seconds per "
           "sequence |\n"
           "|---|---|---|---|---|---|---|---|---|\n";
  for (const ShortSequenceResult& result : results) {
    table << "| " << CalibrationMethodName(result.method);
    if (result.num_fallbacks > 0) {
      table << " (rd_ra in " << result.num_fallbacks << ")";
    }
    table << " | " << result.num_sequences << " | " << std::fixed
          << std::setprecision(0) << result.PercentComplete() << "% | "
          << result.PercentGood() << "% | " << std::setprecision(3)
          << MedianWithFailures(result.max_rotation_deg) << " | "
          << std::setprecision(2)
          << 100.0 * MedianWithFailures(result.max_center_error) << " | "
          << std::setprecision(3)
          << MedianWithFailures(result.initial_rotation_deg) << " | "
          << std::setprecision(2)
          << 100.0 * MedianWithFailures(result.initial_center_error) << " | "
          << result.seconds / std::max(1, result.num_sequences) << " |\n";
  }
  return table.str();
}

}  // namespace rig_calibrator
