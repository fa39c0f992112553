// The paper's robustness experiment (§5.3, Table 3): calibrate from many
// short sub-sequences (10 framesets) of a longer recording and count how often
// each method calibrates the complete rig, and how often well (every camera's
// rotation error below 1 degree and camera-center error below 1 cm indoors).
#pragma once

#include <string>
#include <vector>

#include "src/calibration/pipeline.h"
#include "src/experiments/paper_methods.h"
#include "src/synthetic/synthetic_rig.h"

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
  std::vector<CalibrationMethod> methods = RobustnessTableMethods();
  unsigned int seed = 0;
  // Sequences are calibrated in parallel, each on one thread (-1: all
  // cores); results do not depend on it.
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
  // Per camera of every sequence (sequence-major), the rotation (deg) and
  // center errors of the rig as it entered the final bundle adjustment
  // (paper Fig. 6) and of the final rig; infinity where the camera was not
  // calibrated at that point or the sequence failed before it.
  std::vector<double> initial_rotation_deg, initial_center_error;
  std::vector<double> final_rotation_deg, final_center_error;
  // Sequences where 1dr fell back to rd_ra (parallel principal axes).
  int num_fallbacks = 0;
  // Sum of the calibrations' own run times (one thread each).
  double seconds = 0;

  double PercentComplete() const;
  double PercentGood() const;
};

// Runs every method on the same sequences. Deterministic for a seed.
std::vector<ShortSequenceResult> RunShortSequenceExperiment(
    const ShortSequenceOptions& options);

// A Markdown table: method, sequences, % complete, % good, median errors
// (final and initial), seconds per sequence.
std::string FormatShortSequenceResults(
    const std::vector<ShortSequenceResult>& results);

// The median (colmap::Median: the mean of the two middle values for an even
// count) with failures as infinity, ranking above every error: infinity when
// at least half failed; NaN for no values.
double MedianWithFailures(const std::vector<double>& values);

}  // namespace rig_calibrator
