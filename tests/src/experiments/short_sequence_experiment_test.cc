#include "src/experiments/short_sequence_experiment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace rig_calibrator {
namespace short_sequence_experiment_test {

// A smaller version of the README's 100-sequence experiment (run with
// `rig_calibrator_lab benchmark`): 1dr must calibrate almost every short
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

// Equal up to the rounding of the solves (the sequences run on parallel
// threads, and results vary in the last digits).
void ExpectNear(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_NEAR(a[k], b[k], 1e-6 * std::abs(b[k])) << k;
  }
}

// Each method is run on the same sequences with the same seeds, whichever
// other methods run with it: a method's results are those of running it
// alone. (Sequences drawn anew per method, or seeds that depend on the
// method's position in the list, would give other sequences.)
TEST(ShortSequenceExperiment, EveryMethodSeesTheSameSequences) {
  ShortSequenceOptions options;
  options.recording.num_framesets = 30;
  options.num_sequences = 3;
  options.framesets_per_sequence = 5;
  options.methods = {CalibrationMethod::kRdRa, CalibrationMethod::kRadial1D};
  const std::vector<ShortSequenceResult> together =
      RunShortSequenceExperiment(options);
  ASSERT_EQ(together.size(), 2u);
  for (size_t m = 0; m < 2; ++m) {
    SCOPED_TRACE(CalibrationMethodName(options.methods[m]));
    ShortSequenceOptions alone = options;
    alone.methods = {options.methods[m]};
    const std::vector<ShortSequenceResult> results =
        RunShortSequenceExperiment(alone);
    ASSERT_EQ(results.size(), 1u);
    EXPECT_EQ(results[0].method, together[m].method);
    EXPECT_EQ(results[0].num_complete, together[m].num_complete);
    ExpectNear(results[0].max_rotation_deg, together[m].max_rotation_deg);
    ExpectNear(results[0].final_center_error, together[m].final_center_error);
    ExpectNear(results[0].initial_center_error,
               together[m].initial_center_error);
  }
  // The two methods did calibrate, each its own way: their initial rigs
  // differ by far more than rounding.
  EXPECT_GT(std::abs(MedianWithFailures(together[0].initial_center_error) -
                     MedianWithFailures(together[1].initial_center_error)),
            1e-4);
}

TEST(ShortSequenceExperiment, MedianWithFailuresRanksFailuresLast) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(MedianWithFailures({3, 1, 2}), 2);
  EXPECT_DOUBLE_EQ(MedianWithFailures({4, 1, 2, 3}), 2.5);
  EXPECT_DOUBLE_EQ(MedianWithFailures({inf, 1, 2}), 2);
  EXPECT_EQ(MedianWithFailures({inf, 1, inf}), inf);
  EXPECT_TRUE(std::isnan(MedianWithFailures({})));
}

}  // namespace short_sequence_experiment_test
}  // namespace rig_calibrator
