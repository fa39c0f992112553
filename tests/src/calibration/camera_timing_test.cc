#include "src/calibration/camera_timing.h"

#include <gtest/gtest.h>

#include <cmath>

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
// The time model's estimates as camera timings: only the kinds it kept
// (offsets not kept are the 0 the adjustment assumed, line delays not kept
// are absent); none when it kept neither.
TEST(CameraTiming, AdjustedTimingsOfTheTimeModel) {
  CaptureTimeModel model;
  EXPECT_TRUE(AdjustedCameraTimings(model).empty());
  model.computed = true;
  model.cameras.resize(2);
  model.cameras[1].time_offset_estimated = true;
  model.cameras[1].time_offset_s = 0.03;
  model.cameras[1].time_offset_sigma_s = 2e-4;
  model.cameras[0].line_delay_estimated = true;
  model.cameras[0].line_delay_s = 2.5e-5;
  model.cameras[0].line_delay_sigma_s = 1e-7;
  model.cameras[1].line_delay_estimated = true;
  model.cameras[1].line_delay_s = 3e-5;
  model.cameras[1].line_delay_sigma_s = std::nan("");
  EXPECT_TRUE(AdjustedCameraTimings(model).empty());  // neither kept

  model.time_offsets_kept = true;
  std::vector<std::optional<CameraTiming>> timings =
      AdjustedCameraTimings(model);
  ASSERT_EQ(timings.size(), 2u);
  ASSERT_TRUE(timings[0] && timings[1]);
  EXPECT_EQ(timings[0]->time_offset_s, 0);
  EXPECT_EQ(timings[1]->time_offset_s, 0.03);
  EXPECT_EQ(timings[1]->time_offset_sigma_s, 2e-4);
  EXPECT_FALSE(timings[1]->line_delay_s_per_row);
  EXPECT_EQ(timings[1]->source, TimingSource::kEstimatedInAdjustment);

  model.time_offsets_kept = false;
  model.line_delays_kept = true;
  timings = AdjustedCameraTimings(model);
  ASSERT_EQ(timings.size(), 2u);
  EXPECT_EQ(timings[1]->time_offset_s, 0);
  EXPECT_EQ(timings[1]->time_offset_sigma_s, 0);
  ASSERT_TRUE(timings[0]->line_delay_s_per_row);
  EXPECT_EQ(*timings[0]->line_delay_s_per_row, 2.5e-5);
  EXPECT_EQ(timings[0]->line_delay_sigma_s_per_row, 1e-7);
  // A sigma the covariance could not give reads "?" in the result table.
  EXPECT_EQ(CameraTimingText(*timings[1]),
            "dt +0.00 +- 0.00 ms line 30.00 +- ? us/row");
}

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
