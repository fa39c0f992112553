#include "src/experiments/short_sequence_experiment.h"

#include <gtest/gtest.h>

namespace rig_calibrator {
namespace {

// A smaller version of the README's 100-sequence experiment (run with
// `rig_calibrator benchmark`): 1dr must calibrate almost every short
// sequence well.
TEST(ShortSequenceExperiment, RadialMethodIsRobustOnShortSequences) {
  ShortSequenceOptions options;
  options.recording.preset = RigPreset::kRing5;
  options.recording.num_framesets = 60;
  options.recording.seed = 3;
  options.num_sequences = 10;
  options.methods = {CalibrationMethod::kRadial1D};
  const std::vector<ShortSequenceResult> results =
      RunShortSequenceExperiment(options);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].num_sequences, 10);
  EXPECT_GE(results[0].num_good, 9) << FormatShortSequenceResults(results);
}

TEST(ShortSequenceExperiment, SequencesAreTheSameForEveryMethod) {
  ShortSequenceOptions options;
  options.recording.num_framesets = 30;
  options.num_sequences = 2;
  options.framesets_per_sequence = 5;
  options.methods = {CalibrationMethod::kRadial1D,
                     CalibrationMethod::kRadial1D};
  const std::vector<ShortSequenceResult> results =
      RunShortSequenceExperiment(options);
  ASSERT_EQ(results.size(), 2u);
  // Same sequences and seeds: the same result up to the rounding of Ceres's
  // multi-threaded evaluation.
  ASSERT_EQ(results[0].max_rotation_deg.size(), 2u);
  ASSERT_EQ(results[1].max_rotation_deg.size(), 2u);
  for (int s = 0; s < 2; ++s) {
    EXPECT_NEAR(results[0].max_rotation_deg[s], results[1].max_rotation_deg[s],
                1e-6);
  }
}

}  // namespace
}  // namespace rig_calibrator
