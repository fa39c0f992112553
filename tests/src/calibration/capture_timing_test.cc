// The capture-time offsets after a calibration (capture_timing.h): on the
// time model's data (ring5 at 5 Hz, default noise and wrong matches, the
// true camera models given) the warning unsynchronized_cameras names the
// cameras with offsets in +-50 ms and the offsets match the truth; the same
// data synchronized stay quiet; without frameset times nothing is computed
// and the calibration is the same; and the significance test's parts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "src/calibration/capture_timing.h"
#include "src/calibration/pipeline.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace capture_timing_test {

// 80 framesets at 5 Hz (16 s of the profile's turns); offsets drawn in
// +-50 ms (max_time_offset_s) or given.
SyntheticRig TimedRing(double max_time_offset_s,
                       std::vector<double> time_offsets_s = {}) {
  SyntheticRigOptions options;
  options.preset = RigPreset::kRing5;
  options.num_framesets = 80;
  options.points_per_image = 120;
  options.frameset_rate_hz = 5;
  options.max_time_offset_s = max_time_offset_s;
  options.time_offsets_s = std::move(time_offsets_s);
  options.seed = 7;
  SyntheticRig rig = GenerateSyntheticRig(options);
  SetKnownIntrinsics(&rig);
  return rig;
}

struct TimedRun {
  RigCalibration calibration;
  PipelineReport report;
};

TimedRun Calibrate(const RigDataset& dataset) {
  PipelineOptions options;
  options.method = CalibrationMethod::kKnown;
  options.print_progress = false;
  // The measurement after today's calibration: the final adjustment's time
  // model (capture_time_model_test.cc) off.
  options.capture_time_model.time_offsets = CaptureTimeMode::kOff;
  options.capture_time_model.rolling_shutter = CaptureTimeMode::kOff;
  TimedRun run;
  EXPECT_TRUE(
      CalibrateRig(options, dataset, &run.calibration, &run.report))
      << run.report.error;
  return run;
}

const Diagnostic* FindDiagnostic(const PipelineReport& report,
                                 const std::string& code) {
  for (const Diagnostic& diagnostic : report.diagnostics) {
    if (diagnostic.code == code) return &diagnostic;
  }
  return nullptr;
}

TEST(CaptureTiming, UnsynchronizedCamerasAreMeasuredAndNamed) {
  const SyntheticRig rig = TimedRing(0.05);
  const TimedRun run = Calibrate(rig.dataset);
  const CaptureTiming& timing = run.report.capture_timing;
  ASSERT_TRUE(timing.computed);
  ASSERT_TRUE(timing.error.empty()) << timing.error;
  ASSERT_EQ(timing.offsets.size(), rig.truth.time_offsets_s.size());
  const Diagnostic* warning =
      FindDiagnostic(run.report, "unsynchronized_cameras");
  ASSERT_NE(warning, nullptr);
  EXPECT_EQ(warning->level, Diagnostic::Level::kWarning);
  EXPECT_NE(warning->message.find("assumes that every frameset was taken at "
                                  "one instant"),
            std::string::npos)
      << warning->message;
  for (size_t c = 1; c < timing.offsets.size(); ++c) {
    const CameraTimeOffset& offset = timing.offsets[c];
    const double truth = rig.truth.time_offsets_s[c];
    const double error = offset.offset_s - truth;
    std::cout << "cam" << c << " truth " << truth * 1e3 << " ms, estimate "
              << offset.offset_s * 1e3 << " +- " << offset.offset_sigma_s * 1e3
              << " ms, error / sigma " << error / offset.offset_sigma_s
              << std::endl;
    ASSERT_TRUE(offset.observable) << offset.diagnosis;
    EXPECT_LT(std::abs(error), 4 * offset.offset_sigma_s);
    EXPECT_LT(std::abs(error), 1e-3);
    const bool named = std::count(warning->cameras.begin(),
                                  warning->cameras.end(), static_cast<int>(c));
    // Every offset above 5 ms is named, none below the 1 ms floor.
    if (std::abs(truth) > 5e-3) EXPECT_TRUE(named) << c;
    if (std::abs(truth) < 1e-3) EXPECT_FALSE(named) << c;
    EXPECT_EQ(named, static_cast<bool>(timing.significant[c]));
    if (named) {
      EXPECT_NE(warning->message.find("cam" + std::to_string(c)),
                std::string::npos);
    }
  }
}

// Synchronized: the same rig and motion with every offset 0 gives offsets
// near 0 and no warning; without frameset times nothing is measured and the
// calibration is the same, bit for bit.
TEST(CaptureTiming, SynchronizedIsQuietAndNoTimesMeansNothing) {
  const SyntheticRig rig = TimedRing(0, {0, 0, 0, 0, 0});
  const TimedRun run = Calibrate(rig.dataset);
  const CaptureTiming& timing = run.report.capture_timing;
  ASSERT_TRUE(timing.computed);
  ASSERT_TRUE(timing.error.empty()) << timing.error;
  EXPECT_EQ(FindDiagnostic(run.report, "unsynchronized_cameras"), nullptr);
  for (size_t c = 1; c < timing.offsets.size(); ++c) {
    std::cout << "cam" << c << " estimate " << timing.offsets[c].offset_s * 1e3
              << " +- " << timing.offsets[c].offset_sigma_s * 1e3 << " ms"
              << std::endl;
    EXPECT_TRUE(timing.offsets[c].observable) << timing.offsets[c].diagnosis;
    EXPECT_LT(std::abs(timing.offsets[c].offset_s), 1e-3);
    EXPECT_FALSE(timing.significant[c]);
  }

  RigDataset untimed = rig.dataset;
  untimed.frameset_times_s.clear();
  const TimedRun plain = Calibrate(untimed);
  EXPECT_FALSE(plain.report.capture_timing.computed);
  EXPECT_TRUE(plain.report.capture_timing.offsets.empty());
  ASSERT_EQ(plain.report.timings.size() + 1, run.report.timings.size());
  for (const StageTiming& timing : plain.report.timings) {
    EXPECT_NE(timing.stage, "Capture-time offsets");
  }
  ASSERT_EQ(plain.report.diagnostics.size(), run.report.diagnostics.size());
  for (size_t i = 0; i < run.report.diagnostics.size(); ++i) {
    EXPECT_EQ(plain.report.diagnostics[i].message,
              run.report.diagnostics[i].message);
  }
  for (size_t c = 0; c < rig.dataset.cameras.size(); ++c) {
    EXPECT_EQ(plain.calibration.cameras[c].Params(),
              run.calibration.cameras[c].Params());
    EXPECT_EQ(plain.calibration.cam_from_rig[c].translation,
              run.calibration.cam_from_rig[c].translation);
  }
}

// Each part of the test: observable, 3 sigma, the 1 ms floor, and the rig's
// rotation during the offset against the calibration's rotation sigma.
TEST(CaptureTiming, SignificanceNeedsEveryPart) {
  const CaptureTimingOptions options;
  CameraTimeOffset offset;
  offset.observable = true;
  offset.offset_s = -0.004;
  offset.offset_sigma_s = 0.001;
  const double speed = 0.5;  // rad/s: 2 mrad of rotation during 4 ms
  EXPECT_TRUE(OffsetIsSignificant(offset, speed, 1e-3, options));
  // The calibration's own rotation sigma is larger than the rotation.
  EXPECT_FALSE(OffsetIsSignificant(offset, speed, 3e-3, options));
  // Without a rotation sigma that part is skipped.
  EXPECT_TRUE(OffsetIsSignificant(offset, speed, 0, options));
  EXPECT_TRUE(OffsetIsSignificant(offset, speed, NAN, options));
  offset.offset_sigma_s = 0.0014;  // |delta| < 3 sigma
  EXPECT_FALSE(OffsetIsSignificant(offset, speed, 1e-3, options));
  offset.offset_sigma_s = INFINITY;
  EXPECT_FALSE(OffsetIsSignificant(offset, speed, 1e-3, options));
  offset.offset_sigma_s = 0.0001;
  offset.offset_s = 0.0009;  // below the 1 ms floor, 9 sigma
  EXPECT_FALSE(OffsetIsSignificant(offset, 10.0, 1e-4, options));
  offset.offset_s = 0.0011;
  EXPECT_TRUE(OffsetIsSignificant(offset, 10.0, 1e-4, options));
  offset.observable = false;
  EXPECT_FALSE(OffsetIsSignificant(offset, 10.0, 1e-4, options));
}

}  // namespace capture_timing_test
}  // namespace rig_calibrator
