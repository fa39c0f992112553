#include "src/calibration/camera_timing.h"

#include <gtest/gtest.h>

namespace rig_calibrator {
namespace camera_timing_test {

// The measured offsets of capture_timing as camera timings: the observable
// ones and the reference's 0; none when the step did not run, failed, or
// no camera's offset is observable.
TEST(CameraTiming, MeasuredTimingsOfTheCaptureTimingStep) {
  CaptureTiming timing;
  EXPECT_TRUE(MeasuredCameraTimings(timing, 0).empty());
  timing.computed = true;
  timing.offsets.resize(3);
  timing.significant = {false, true, false};
  EXPECT_TRUE(MeasuredCameraTimings(timing, 0).empty());
  timing.offsets[1].observable = true;
  timing.offsets[1].offset_s = 0.02;
  timing.offsets[1].offset_sigma_s = 0.001;
  const std::vector<std::optional<CameraTiming>> timings =
      MeasuredCameraTimings(timing, 0);
  ASSERT_EQ(timings.size(), 3u);
  ASSERT_TRUE(timings[0] && timings[1]);
  EXPECT_FALSE(timings[2]);
  EXPECT_EQ(timings[0]->time_offset_s, 0);
  EXPECT_EQ(timings[1]->time_offset_s, 0.02);
  EXPECT_EQ(timings[1]->time_offset_sigma_s, 0.001);
  EXPECT_FALSE(timings[1]->line_delay_s_per_row);
  EXPECT_EQ(timings[1]->source, TimingSource::kMeasuredAfterCalibration);
  EXPECT_EQ(TimingSourceFromName(TimingSourceName(
                TimingSource::kEstimatedInAdjustment)),
            TimingSource::kEstimatedInAdjustment);
  EXPECT_FALSE(TimingSourceFromName("guessed"));
  timing.error = "too few framesets";
  EXPECT_TRUE(MeasuredCameraTimings(timing, 0).empty());
}

// The result table's columns: the offset in ms, the line delay in us/row
// only when estimated.
TEST(CameraTiming, TextOfTheResultTable) {
  CameraTiming timing;
  timing.time_offset_s = 0.0482;
  timing.time_offset_sigma_s = 0.00031;
  EXPECT_EQ(CameraTimingText(timing), "dt +48.20 +- 0.31 ms");
  timing.time_offset_s = -0.0125;
  timing.line_delay_s_per_row = 2.91e-5;
  timing.line_delay_sigma_s_per_row = 4e-7;
  EXPECT_EQ(CameraTimingText(timing),
            "dt -12.50 +- 0.31 ms line 29.10 +- 0.40 us/row");
}

}  // namespace camera_timing_test
}  // namespace rig_calibrator
