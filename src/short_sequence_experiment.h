// The paper's robustness experiment (§5.3, Table 3): calibrate from many
// short sub-sequences (10 framesets) of a longer recording and count how often
// each method calibrates the complete rig, and how often well (every camera's
// rotation error below 1 degree and camera-center error below 1 cm indoors).
#pragma once

#include <string>
#include <vector>

#include "src/pipeline.h"
#include "src/synthetic_rig.h"

namespace rig_calibrator {

struct ShortSequenceOptions {
  SyntheticRigOptions recording;  // the long recording sequences are cut from
  int num_sequences = 100;
  int framesets_per_sequence = 10;
  // Framesets of a sequence are this many recording framesets apart (the
  // paper takes framesets about one second apart).
  int frameset_stride = 2;
  double good_rotation_deg = 1.0;
  double good_center_error = 0.01;  // map units (metres for metric maps)
  std::vector<CalibrationMethod> methods = {CalibrationMethod::kRd,
                                            CalibrationMethod::kRdRa,
                                            CalibrationMethod::kRadial1D};
  unsigned int seed = 0;
  int num_threads = -1;
};

struct ShortSequenceResult {
  CalibrationMethod method = CalibrationMethod::kRadial1D;
  int num_sequences = 0;
  int num_complete = 0;  // every camera calibrated
  int num_good = 0;      // complete, and every camera within the bounds
  // Per sequence, the largest error over the cameras (infinity when not
  // complete).
  std::vector<double> max_rotation_deg;
  std::vector<double> max_center_error;
  double seconds = 0;

  double PercentComplete() const;
  double PercentGood() const;
};

// Runs every method on the same sequences. Deterministic for a seed.
std::vector<ShortSequenceResult> RunShortSequenceExperiment(
    const ShortSequenceOptions& options);

// A Markdown table: method, sequences, % complete, % good, median errors.
std::string FormatShortSequenceResults(
    const std::vector<ShortSequenceResult>& results);

}  // namespace rig_calibrator
