// The final adjustment's time model (final_bundle_adjuster.h,
// frameset_motion.h, capture_time_model.h) on the synthetic time model's data
// (ring5 at 15 Hz, 1.5 m/s, turns up to 60 deg/s): the motion model's own
// error; exact data with offsets recovered to that error, from the truth
// and from the capture-timing estimate; noisy data with wrong matches,
// offsets in +-50 ms and line delays, as accurate as synchronized data;
// synchronized global-shutter data with auto left exactly as without the
// model; the model asked for without frameset times is an error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "src/calibration/calibration_uncertainty.h"
#include "src/calibration/capture_time_model.h"
#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/pipeline.h"
#include "src/geometry/frameset_motion.h"
#include "src/geometry/pose_interpolation.h"
#include "src/synthetic/capture_model.h"
#include "src/synthetic/synthetic_rig.h"
#include "tests/src/calibration/calibration_at_truth.h"

namespace rig_calibrator {
namespace capture_time_model_test {

// The tests' frameset rate: 15 Hz (why not 5 Hz: the motion-model test).
constexpr double kRateHz = 15;

SyntheticRigOptions TimedRingOptions(int num_framesets, int points_per_image,
                                     double rate_hz) {
  SyntheticRigOptions options;
  options.preset = RigPreset::kRing5;
  options.num_framesets = num_framesets;
  options.points_per_image = points_per_image;
  options.frameset_rate_hz = rate_hz;
  options.seed = 11;
  return options;
}

SyntheticRigOptions Exact(SyntheticRigOptions options) {
  options.noise_px = 0;
  options.outlier_ratio = 0;
  options.missing_image_ratio = 0;
  return options;
}

// Worst rotation (degrees) and centre (map units) error of the non-reference
// cameras' cam_from_rig.
struct RigError {
  double rotation_deg = 0, centre = 0;
};
RigError ErrorOfRig(const RigCalibration& calibration,
                    const RigGroundTruth& truth) {
  RigError error;
  for (size_t c = 1; c < truth.cam_from_rig.size(); ++c) {
    error.rotation_deg =
        std::max(error.rotation_deg,
                 RotationDifferenceDeg(calibration.cam_from_rig[c].rotation,
                                       truth.cam_from_rig[c].rotation));
    error.centre = std::max(error.centre,
                            (calibration.cam_from_rig[c].Center() -
                             truth.cam_from_rig[c].Center())
                                .norm());
  }
  return error;
}

// rig_from_world(t_f + tau) = M_f(tau)^-1 Q_f (frameset_motion.h) as a pose.
Rigid3d ModelPoseAt(const FramesetMotion& motion, const Rigid3d& rig_from_world,
                    double tau) {
  Eigen::Vector3d u, p;
  for (int k = 0; k < 3; ++k) {
    u(k) = tau * motion[k] + tau * tau / 2 * motion[3 + k] +
           tau * tau * tau / 6 * motion[6 + k];
    p(k) = tau * motion[9 + k] + tau * tau / 2 * motion[12 + k] +
           tau * tau * tau / 6 * motion[15 + k];
  }
  return Rigid3d(ExpSO3(u), p).Inverse() * rig_from_world;
}

// The model's error against the true trajectory, from the true rig poses,
// over every frameset and |tau| up to 80 ms (a 50 ms offset plus a rolling
// shutter's readout) within the framesets' time span, and the first-order
// model's (constant twist).
struct ModelError {
  double rotation_deg = 0, position = 0, first_order_rotation_deg = 0,
         first_order_position = 0;
};
ModelError MotionModelError(double rate_hz) {
  const SyntheticRig rig =
      GenerateSyntheticRig(TimedRingOptions(6 * rate_hz, 10, rate_hz));
  std::vector<std::optional<Rigid3d>> poses(rig.truth.rig_from_world.begin(),
                                            rig.truth.rig_from_world.end());
  std::vector<FramesetMotion> motions;
  std::string error;
  EXPECT_TRUE(ComputeFramesetMotions(rig.truth.frameset_times_s, poses,
                                     &motions, &error))
      << error;
  ModelError result;
  for (size_t f = 0; f < motions.size(); ++f) {
    FramesetMotion first_order = motions[f];
    for (int k : {3, 4, 5, 6, 7, 8, 12, 13, 14, 15, 16, 17}) {
      first_order[k] = 0;
    }
    for (const double tau : {-0.08, -0.05, -0.02, 0.02, 0.05, 0.08}) {
      // Within the framesets' time span (beyond it the motion is
      // extrapolated: cm in position 80 ms beyond the ends).
      const double time = rig.truth.frameset_times_s[f] + tau;
      if (time < rig.truth.frameset_times_s.front() ||
          time > rig.truth.frameset_times_s.back()) {
        continue;
      }
      const Rigid3d truth = RigFromWorldAtTime(
          rig.truth, rig.truth.frameset_times_s[f] + tau);
      const Rigid3d model =
          ModelPoseAt(motions[f], rig.truth.rig_from_world[f], tau);
      const Rigid3d linear =
          ModelPoseAt(first_order, rig.truth.rig_from_world[f], tau);
      result.rotation_deg =
          std::max(result.rotation_deg,
                   RotationDifferenceDeg(model.rotation, truth.rotation));
      result.position = std::max(result.position,
                                 (model.Center() - truth.Center()).norm());
      result.first_order_rotation_deg =
          std::max(result.first_order_rotation_deg,
                   RotationDifferenceDeg(linear.rotation, truth.rotation));
      result.first_order_position =
          std::max(result.first_order_position,
                   (linear.Center() - truth.Center()).norm());
    }
  }
  std::cout << rate_hz << " Hz, |tau| <= 80 ms: third order "
            << result.rotation_deg << " deg, " << result.position * 1e3
            << " mm; first order " << result.first_order_rotation_deg
            << " deg, " << result.first_order_position * 1e3 << " mm"
            << std::endl;
  return result;
}

// The synthetic walk's 3 cm height bob has a period of 2 profile steps,
// 0.43 s at 60 deg/s: at 5 Hz it is sampled at 2.3 frames per period and no
// model through the frameset poses follows it (measured 0.0065 deg, 51 mm;
// first order 0.19 deg, 97 mm); at the tests' 15 Hz the third-order model
// is within 0.0004 deg and 2 mm (first order 0.19 deg, 19 mm).
TEST(CaptureTimeModel, ThirdOrderMotionModelErrorOnTheSyntheticTrajectory) {
  MotionModelError(5);
  const ModelError error = MotionModelError(kRateHz);
  EXPECT_LT(error.rotation_deg, 0.002);
  EXPECT_LT(error.position, 3e-3);
  EXPECT_GT(error.first_order_rotation_deg, 10 * error.rotation_deg);
}

FinalBundleAdjustmentOptions TimeModelOptions() {
  FinalBundleAdjustmentOptions options;
  options.estimate_time_offsets = true;
  options.num_threads = 2;
  return options;
}

// Exact data, offsets in +-50 ms, global shutters; the adjustment starts at
// the truth (offsets included). The offsets come back to the model's own
// error (above: the pose at t_f + delta is off by up to ~1e-3 deg, i.e.
// ~1e-5 s of the rig's motion at 60 deg/s).
TEST(CaptureTimeModel, ExactDataOffsetsFromTheTruth) {
  SyntheticRigOptions options = Exact(TimedRingOptions(60, 40, kRateHz));
  options.max_time_offset_s = 0.05;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  RigCalibration calibration = testing::CalibrationAtTruth(rig);
  FinalBundleAdjustmentOptions ba = TimeModelOptions();
  ba.initial_time_offsets_s = rig.truth.time_offsets_s;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(ba, rig.dataset, &calibration, &summary));
  ASSERT_EQ(summary.capture_times.size(), 5u);
  double max_error = 0;
  for (size_t c = 1; c < 5; ++c) {
    const CameraCaptureTime& time = summary.capture_times[c];
    EXPECT_TRUE(time.time_offset_estimated);
    EXPECT_FALSE(time.line_delay_estimated);
    max_error = std::max(
        max_error, std::abs(time.time_offset_s - rig.truth.time_offsets_s[c]));
  }
  const RigError rig_error = ErrorOfRig(calibration, rig.truth);
  std::cout << "exact data from the truth: offsets within " << max_error * 1e6
            << " us, rig " << rig_error.rotation_deg << " deg, "
            << rig_error.centre * 1e3 << " mm, RMS " << summary.final_rms_px
            << " px" << std::endl;
  EXPECT_FALSE(summary.capture_times[0].time_offset_estimated);
  EXPECT_EQ(summary.capture_times[0].time_offset_s, 0.0);
  EXPECT_LT(max_error, 2e-5);
  EXPECT_LT(rig_error.rotation_deg, 2e-3);
  EXPECT_LT(summary.final_rms_px, 0.02);
}

// The same exact data through the pipeline's step: today's adjustment (no
// time model) from the truth's intrinsics, then the time model from the
// estimated start (on), not from the truth. CalibrationAtTruth has no
// single-image localizations, so no camera's start comes from the
// orientations: this is the capture-timing fallback's start.
TEST(CaptureTimeModel, ExactDataOffsetsFromTheEstimatorStart) {
  SyntheticRigOptions options = Exact(TimedRingOptions(60, 40, kRateHz));
  options.max_time_offset_s = 0.05;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  RigCalibration calibration = testing::CalibrationAtTruth(rig);
  FinalBundleAdjustmentOptions ba;
  ba.num_threads = 2;
  ASSERT_TRUE(AdjustRig(ba, rig.dataset, &calibration, nullptr));
  const RigError today = ErrorOfRig(calibration, rig.truth);
  CaptureTimeModelOptions model_options;
  model_options.time_offsets = CaptureTimeMode::kOn;
  model_options.rolling_shutter = CaptureTimeMode::kOff;
  CaptureTimeModel model;
  std::string error;
  ASSERT_TRUE(AdjustRigWithCaptureTimeModel(model_options, ba, rig.dataset,
                                            &calibration, &model, &error))
      << error;
  ASSERT_TRUE(model.computed);
  EXPECT_TRUE(model.time_offsets_kept);
  EXPECT_FALSE(model.line_delays_kept);
  double max_error = 0;
  for (size_t c = 1; c < 5; ++c) {
    max_error = std::max(max_error, std::abs(model.cameras[c].time_offset_s -
                                             rig.truth.time_offsets_s[c]));
    EXPECT_TRUE(model.time_offset_significant[c] ||
                std::abs(rig.truth.time_offsets_s[c]) < 2e-3);
  }
  const RigError rig_error = ErrorOfRig(calibration, rig.truth);
  std::cout << "exact data from the estimator's start: offsets within "
            << max_error * 1e6 << " us, rig " << rig_error.rotation_deg
            << " deg, " << rig_error.centre * 1e3 << " mm (without the model "
            << today.rotation_deg << " deg, " << today.centre * 1e3
            << " mm); " << model.message << std::endl;
  EXPECT_LT(max_error, 5e-5);
  EXPECT_LT(rig_error.rotation_deg, 2e-3);
}

struct TimedRun {
  RigCalibration calibration;
  PipelineReport report;
};

bool Warns(const PipelineReport& report, const std::string& code) {
  return std::any_of(report.diagnostics.begin(), report.diagnostics.end(),
                     [&](const Diagnostic& d) { return d.code == code; });
}

TimedRun Calibrate(const RigDataset& dataset, CaptureTimeMode offsets,
              CaptureTimeMode shutter) {
  PipelineOptions options;
  options.method = CalibrationMethod::kKnownRefine;
  options.print_progress = false;
  options.num_threads = 2;
  options.capture_time_model.time_offsets = offsets;
  options.capture_time_model.rolling_shutter = shutter;
  TimedRun run;
  EXPECT_TRUE(CalibrateRig(options, dataset, &run.calibration, &run.report))
      << run.report.error;
  return run;
}

SyntheticRig NoisyRig(bool synchronized, int image_height = 0) {
  SyntheticRigOptions options = TimedRingOptions(120, 60, kRateHz);
  options.image_height = image_height;
  if (synchronized) {
    options.time_offsets_s = {0, 0, 0, 0, 0};
    options.line_delays_s = {0, 0, 0, 0, 0};
  } else {
    options.max_time_offset_s = 0.05;
    options.min_line_delay_s = 20e-6;
    options.max_line_delay_s = 30e-6;
  }
  SyntheticRig rig = GenerateSyntheticRig(options);
  SetKnownIntrinsics(&rig);
  return rig;
}

// Noisy data (0.5 px, 30 % wrong matches, 10 % missing images), offsets in
// +-50 ms and line delays in [20, 30] us per row, the default auto modes,
// from the capture-timing estimate: offsets within 0.5 ms, line delays
// within 5 %, and the rig within 1.25 times the error of the same rig and
// motion synchronized with global shutters (plus 0.002 deg / 0.2 mm: both
// are at the noise's level; rotation_factor in place of 1.25 for the
// rotation). image_height 0: the preset's 480 rows.
void ExpectAsAccurateAsSynchronized(int image_height,
                                    double rotation_factor = 1.25) {
  const SyntheticRig synchronized = NoisyRig(true, image_height);
  const TimedRun reference = Calibrate(synchronized.dataset, CaptureTimeMode::kAuto,
                                  CaptureTimeMode::kAuto);
  const RigError reference_error =
      ErrorOfRig(reference.calibration, synchronized.truth);

  const SyntheticRig rig = NoisyRig(false, image_height);
  const TimedRun run =
      Calibrate(rig.dataset, CaptureTimeMode::kAuto, CaptureTimeMode::kAuto);
  const CaptureTimeModel& model = run.report.capture_time_model;
  ASSERT_TRUE(model.computed);
  EXPECT_TRUE(model.time_offsets_kept) << model.message;
  EXPECT_TRUE(model.line_delays_kept) << model.message;
  std::cout << model.message << std::endl;
  for (size_t c = 0; c < 5; ++c) {
    const CameraCaptureTime& time = model.cameras[c];
    const double offset_error = time.time_offset_s - rig.truth.time_offsets_s[c];
    const double delay_error = time.line_delay_s - rig.truth.line_delays_s[c];
    std::cout << "cam" << c << " offset error " << offset_error * 1e6
              << " us (sigma " << time.time_offset_sigma_s * 1e6
              << "), line delay " << time.line_delay_s * 1e6 << " us/row, truth "
              << rig.truth.line_delays_s[c] * 1e6 << " (sigma "
              << time.line_delay_sigma_s * 1e6 << ")" << std::endl;
    EXPECT_LT(std::abs(offset_error), 5e-4) << c;
    EXPECT_LT(std::abs(delay_error), 0.05 * rig.truth.line_delays_s[c]) << c;
    if (c > 0) {
      EXPECT_TRUE(std::isfinite(time.time_offset_sigma_s));
      EXPECT_LT(std::abs(offset_error), 5 * time.time_offset_sigma_s) << c;
    }
    EXPECT_LT(std::abs(delay_error), 5 * time.line_delay_sigma_s) << c;
  }
  const RigError error = ErrorOfRig(run.calibration, rig.truth);
  const TimedRun without =
      Calibrate(rig.dataset, CaptureTimeMode::kOff, CaptureTimeMode::kOff);
  const RigError without_error = ErrorOfRig(without.calibration, rig.truth);
  std::cout << "rig error: synchronized " << reference_error.rotation_deg
            << " deg, " << reference_error.centre * 1e3
            << " mm; unsynchronized with the time model " << error.rotation_deg
            << " deg, " << error.centre * 1e3 << " mm; without it "
            << without_error.rotation_deg << " deg, "
            << without_error.centre * 1e3 << " mm" << std::endl;
  EXPECT_LT(error.rotation_deg,
            rotation_factor * reference_error.rotation_deg + 0.002);
  EXPECT_LT(error.centre, 1.25 * reference_error.centre + 2e-4);
  // The precision, free of one draw's luck: every camera's rotation and
  // centre sigma within 1.25 times the synchronized rig's.
  const std::vector<CameraUncertainty>& sigmas =
      run.report.uncertainty.cameras;
  const std::vector<CameraUncertainty>& reference_sigmas =
      reference.report.uncertainty.cameras;
  ASSERT_EQ(sigmas.size(), 5u);
  ASSERT_EQ(reference_sigmas.size(), 5u);
  for (size_t c = 1; c < 5; ++c) {
    const double centre_sigma = sigmas[c].center_in_rig_stddev.norm();
    const double reference_centre_sigma =
        reference_sigmas[c].center_in_rig_stddev.norm();
    std::cout << "cam" << c << " rotation sigma "
              << sigmas[c].rotation_stddev_deg << " deg (synchronized "
              << reference_sigmas[c].rotation_stddev_deg << "), centre sigma "
              << centre_sigma * 1e3 << " mm (" << reference_centre_sigma * 1e3
              << ")" << std::endl;
    EXPECT_LT(sigmas[c].rotation_stddev_deg,
              1.25 * reference_sigmas[c].rotation_stddev_deg)
        << c;
    EXPECT_LT(centre_sigma, 1.25 * reference_centre_sigma) << c;
  }
  // The warning that the calibration ignores the offsets is gone.
  for (const Diagnostic& diagnostic : run.report.diagnostics) {
    EXPECT_NE(diagnostic.code, "unsynchronized_cameras");
  }
}

// 480 rows: a readout of 10-14 ms.
TEST(CaptureTimeModel, NoisyUnsynchronizedRollingShutterAsAccurateAsSynchronized) {
  ExpectAsAccurateAsSynchronized(0);
}

// 1080 rows (the cameras scaled, intrinsics with them): a readout of 22-32
// ms, the issue's case. The centre within 1.25 times the synchronized
// rig's (0.33 against 0.36 mm), but the rotation 1.5 times (0.0220 against
// 0.0151 deg, seed 11; 0.0225 with the velocities alone estimated):
// asserted at 2 times. Over 8 other seeds the rotation is 1.12 times the
// synchronized rig's RMS (docs/time_model.md, "Over many seeds"). The true
// motion in place of the model gave 0.024 deg: one draw's error of the time
// parameters, not the motion. The interior framesets' motions leave their
// own poses out here (frameset_motion.h).
TEST(CaptureTimeModel, NoisyAt1080RowsNearlyAsAccurateAsSynchronized) {
  ExpectAsAccurateAsSynchronized(1080, 2.0);
}

// scripts/benchmark_time_model.sh's case (d) at `rate_hz`: seed 0, 60
// framesets, 1080 rows, offsets in +-50 ms, 20-30 us per row.
SyntheticRigOptions BenchmarkCaseD(RigPreset preset, double rate_hz) {
  SyntheticRigOptions options = TimedRingOptions(60, 300, rate_hz);
  options.preset = preset;
  options.seed = 0;
  options.image_height = 1080;
  options.max_time_offset_s = 0.05;
  options.min_line_delay_s = 20e-6;
  options.max_line_delay_s = 30e-6;
  return options;
}

// The issue's bounds: every camera's offset within 0.5 ms and line delay
// within 5 % of the truth.
void ExpectTimingWithinTheIssuesBounds(const CaptureTimeModel& model,
                                       const RigGroundTruth& truth) {
  ASSERT_EQ(model.cameras.size(), truth.time_offsets_s.size());
  for (size_t c = 0; c < model.cameras.size(); ++c) {
    EXPECT_LT(std::abs(model.cameras[c].time_offset_s -
                       truth.time_offsets_s[c]),
              5e-4)
        << c;
    EXPECT_LT(std::abs(model.cameras[c].line_delay_s -
                       truth.line_delays_s[c]),
              0.05 * truth.line_delays_s[c])
        << c;
  }
}

// The default method from scratch, every camera's model chosen
// automatically (auto); refine_points: the map points refined, as the
// command's default (--RigCalibrator.refine_points 1).
TimedRun CalibrateWithAutomaticModels(SyntheticRig* rig, bool refine_points) {
  for (RigCamera& camera : rig->dataset.cameras) {
    camera.intrinsics_known = false;
    camera.choose_model = true;
  }
  PipelineOptions options;
  options.print_progress = false;
  options.num_threads = 2;
  options.final_bundle_adjustment.refine_points = refine_points;
  TimedRun run;
  EXPECT_TRUE(CalibrateRig(options, rig->dataset, &run.calibration, &run.report))
      << run.report.error;
  return run;
}

// The user's default path on the same unsynchronized rolling-shutter data:
// method 1dr, every camera's model chosen automatically (auto), the time
// model auto. The time model runs before the model choice on the adjusted
// rig, which takes each observation at its own instant: every camera gets
// its true model (OPENCV), the offsets are within 0.5 ms and the line
// delays within 5 %, and the rig within 0.06 deg and 1.5 mm.
TEST(CaptureTimeModel, DefaultMethodAndAutomaticModelsFromScratch) {
  SyntheticRig rig = NoisyRig(false);
  const TimedRun run = CalibrateWithAutomaticModels(&rig, false);
  const RigCalibration& calibration = run.calibration;
  const PipelineReport& report = run.report;
  const CaptureTimeModel& model = report.capture_time_model;
  std::cout << model.message << std::endl;
  ASSERT_TRUE(model.time_offsets_kept && model.line_delays_kept);
  ExpectTimingWithinTheIssuesBounds(model, rig.truth);
  for (size_t c = 0; c < 5; ++c) {
    EXPECT_EQ(calibration.cameras[c].ModelName(), "OPENCV") << c;
  }
  const RigError error = ErrorOfRig(calibration, rig.truth);
  std::cout << "default method, models auto: rig " << error.rotation_deg
            << " deg, " << error.centre * 1e3 << " mm" << std::endl;
  // Measured 0.038 deg, 0.72 mm; the known-intrinsics run of the same data
  // synchronized: 0.035 deg, 1.22 mm (the test above).
  EXPECT_LT(error.rotation_deg, 0.06);
  EXPECT_LT(error.centre, 1.5e-3);
}

// The same at 5 Hz and 1080 rows, the issue's case (the data of
// scripts/benchmark_time_model.sh's ring5 case (d): seed 0, 60 framesets,
// points refined as by the command). The camera upgrade, on the data
// before the time model, chooses SIMPLE_RADIAL_FISHEYE for cam2's pinhole
// lens, and the points cam2 sees are refined through it. The choice on the
// adjusted rig takes each point as the other images place it
// (points_without_camera.h): every camera gets OPENCV, and the rig is within
// 0.03 deg and 0.8 mm (measured 0.022 deg, 0.67 mm; one draw: over 5 other
// seeds the ring's centre error at 5 Hz is 0.33 mm RMS, 0.27 mm with the
// prior's polynomial held within each solve; 0.34 mm with the
// frameset velocities' deviations taken as independent, which measured
// 0.83 mm on this draw; 0.39 mm with only the velocities estimated). With the
// refined points everywhere cam2 got OPENCV_FISHEYE and the rig was 0.19
// deg off.
TEST(CaptureTimeModel, DefaultPathAt5HzAnd1080RowsChoosesTheTrueModels) {
  SyntheticRig rig =
      GenerateSyntheticRig(BenchmarkCaseD(RigPreset::kRing5, 5));
  const TimedRun run = CalibrateWithAutomaticModels(&rig, true);
  const RigCalibration& calibration = run.calibration;
  const PipelineReport& report = run.report;
  ASSERT_TRUE(report.capture_time_model.time_offsets_kept &&
              report.capture_time_model.line_delays_kept)
      << report.capture_time_model.message;
  for (size_t c = 0; c < 5; ++c) {
    EXPECT_EQ(calibration.cameras[c].ModelName(), "OPENCV") << c;
  }
  // At 5 Hz the framesets do not follow the rig's motion: the sigmas may be
  // too small, and the command says so.
  EXPECT_TRUE(Warns(report, "time_model_framesets_sparse"));
  const RigError error = ErrorOfRig(calibration, rig.truth);
  std::cout << "5 Hz, 1080 rows, models auto: rig " << error.rotation_deg
            << " deg, " << error.centre * 1e3 << " mm" << std::endl;
  EXPECT_LT(error.rotation_deg, 0.03);
  EXPECT_LT(error.centre, 0.8e-3);
}

// The benchmark's case (d) at `rate_hz` on the default path, points
// refined: offsets and line delays kept and within the issue's bounds, the
// sparse-framesets warning as `expect_sparse_warning` says, the rig within
// 0.03 deg and 1.2 mm.
void ExpectCaseDOnTheDefaultPath(RigPreset preset, double rate_hz,
                                 bool expect_sparse_warning) {
  SyntheticRig rig = GenerateSyntheticRig(BenchmarkCaseD(preset, rate_hz));
  const TimedRun run = CalibrateWithAutomaticModels(&rig, true);
  const CaptureTimeModel& model = run.report.capture_time_model;
  ASSERT_TRUE(model.time_offsets_kept && model.line_delays_kept)
      << model.message;
  ExpectTimingWithinTheIssuesBounds(model, rig.truth);
  EXPECT_EQ(Warns(run.report, "time_model_framesets_sparse"),
            expect_sparse_warning);
  const RigError error = ErrorOfRig(run.calibration, rig.truth);
  std::cout << rate_hz << " Hz, 1080 rows, models auto: rig "
            << error.rotation_deg << " deg, " << error.centre * 1e3 << " mm"
            << std::endl;
  EXPECT_LT(error.rotation_deg, 0.03);
  EXPECT_LT(error.centre, 1.2e-3);
}

// The ring's case (d) at 10 Hz: the framesets are 0.1 s apart, and over 5
// seeds the ring's rotation errors at 10 Hz were 1.48 sigma RMS and 1.34
// times the synchronized rig's, as at 5 Hz (docs/time_model.md, "Over many
// seeds"): the command warns. The timing is within the issue's bounds all
// the same, and the rig within the 15 Hz test's bounds (measured
// 0.0091 deg, 0.37 mm; one draw).
TEST(CaptureTimeModel, DefaultPathAt10HzWarnsThatSigmaCanBeTooSmall) {
  ExpectCaseDOnTheDefaultPath(RigPreset::kRing5, 10, true);
}

// The benchmark's helmet case (d) at 15 Hz (scripts/benchmark_time_model.sh
// with FRAMESET_RATE_HZ=15: seed 0, 60 framesets, 1080 rows, offsets in
// +-50 ms, 20-30 us per row; default path, points refined). The images are
// up to 0.8 frameset intervals off the frameset's instant: with every
// frameset's motion through its own pose, the last frameset (without its
// reference camera's image) ran 1.6 m off, its rig pose left the
// uncertainty undetermined, auto kept nothing and the rig was 1.6 deg off
// (frameset_motion.h). Now offsets within 0.5 ms, line delays within 5 %,
// the rig within 0.03 deg and 1.2 mm (measured 0.0231 deg, 0.81 mm; one
// draw: over 8 other seeds the helmet's rotation error at 15 Hz is
// 0.0109 deg RMS against 0.0091 deg synchronized, its centre error
// 0.313 mm against 0.293 mm, docs/time_model.md), and no sparse-framesets
// warning. With only the velocities estimated, not the accelerations, this
// draw measured 0.0129 deg, 0.90 mm, and the 8 seeds 0.0097 deg.
TEST(CaptureTimeModel, DefaultPathAt15HzWithOffsetsNearTheFramesetInterval) {
  ExpectCaseDOnTheDefaultPath(RigPreset::kFisheyeHelmet5, 15, false);
}

// The centre sigma of the car's case (d) at 15 Hz (seed 0, known
// intrinsics, the time model auto) over that of the same data synchronized,
// the largest over the non-reference cameras: of the sigmas' norms, and
// along the rig's y axis. How much less precise offsets and line delays
// make the data. bob_hz 0: the car's own bounce.
struct SigmaRatio {
  double norm = 0, y = 0;
};
SigmaRatio WorstCentreSigmaRatioOfTheCar(double bob_hz) {
  SigmaRatio worst;
  std::vector<CameraUncertainty> sigmas[2];
  for (const bool synchronized : {true, false}) {
    SyntheticRigOptions options =
        BenchmarkCaseD(RigPreset::kCarSurround4, kRateHz);
    options.bob_hz = bob_hz;
    if (synchronized) {
      options.max_time_offset_s = 0;
      options.min_line_delay_s = options.max_line_delay_s = 0;
    }
    SyntheticRig rig = GenerateSyntheticRig(options);
    SetKnownIntrinsics(&rig);
    const TimedRun run =
        Calibrate(rig.dataset, CaptureTimeMode::kAuto, CaptureTimeMode::kAuto);
    EXPECT_EQ(run.report.capture_time_model.time_offsets_kept, !synchronized);
    const RigError error = ErrorOfRig(run.calibration, rig.truth);
    std::cout << (synchronized ? "synchronized" : "offsets, line delays")
              << ", bob " << bob_hz << " Hz: rig " << error.rotation_deg
              << " deg, " << error.centre * 1e3 << " mm" << std::endl;
    sigmas[synchronized ? 0 : 1] = run.report.uncertainty.cameras;
  }
  EXPECT_EQ(sigmas[0].size(), 4u);
  EXPECT_EQ(sigmas[1].size(), 4u);
  for (size_t c = 1; c < std::min(sigmas[0].size(), sigmas[1].size()); ++c) {
    const Eigen::Vector3d& sigma = sigmas[1][c].center_in_rig_stddev;
    const Eigen::Vector3d& reference = sigmas[0][c].center_in_rig_stddev;
    std::cout << "cam" << c
              << " centre sigma (d) / (a): " << sigma.norm() / reference.norm()
              << ", per axis " << sigma.cwiseQuotient(reference).transpose()
              << std::endl;
    worst.norm = std::max(worst.norm, sigma.norm() / reference.norm());
    worst.y = std::max(worst.y, sigma.y() / reference.y());
  }
  return worst;
}

// The car at 15 Hz: with its 1.25 Hz bounce, which the framesets follow,
// unsynchronized rolling-shutter data are as precise as synchronized ones
// (every camera's centre sigma within 1.25 times; per axis up to 1.31
// times, along y); shaking at 4.83 Hz (1 cm, 9 m/s^2, sampled 3.1 times per
// period) the framesets do not follow its velocity, which every camera's
// centre then shares through its offset, and the sigma along the rig's y
// axis (about the vertical, camera 0 being pitched 12 degrees) is several
// times the synchronized one (measured 3.3-6.3 times). With the models
// chosen automatically, over 8 seeds: 1.06 and 1.55 times the sigmas' RMS
// (docs/time_model.md, "Over many seeds").
TEST(CaptureTimeModel, CarAt15HzAsPreciseAsSynchronizedUnlessItShakes) {
  const SigmaRatio bounce = WorstCentreSigmaRatioOfTheCar(0);
  EXPECT_LT(bounce.norm, 1.25);
  EXPECT_LT(bounce.y, 1.5);
  const SigmaRatio shaking = WorstCentreSigmaRatioOfTheCar(4.83);
  EXPECT_GT(shaking.y, 2.5);
}

// Synchronized global shutters: auto estimates, finds nothing significant
// and leaves the calibration exactly as with the model off.
TEST(CaptureTimeModel, SynchronizedGlobalShutterAutoKeepsNothing) {
  SyntheticRigOptions options = TimedRingOptions(60, 60, kRateHz);
  options.time_offsets_s = {0, 0, 0, 0, 0};
  SyntheticRig rig = GenerateSyntheticRig(options);
  SetKnownIntrinsics(&rig);
  const TimedRun automatic =
      Calibrate(rig.dataset, CaptureTimeMode::kAuto, CaptureTimeMode::kAuto);
  const TimedRun off =
      Calibrate(rig.dataset, CaptureTimeMode::kOff, CaptureTimeMode::kOff);
  const CaptureTimeModel& model = automatic.report.capture_time_model;
  ASSERT_TRUE(model.computed);
  std::cout << model.message << std::endl;
  EXPECT_FALSE(model.time_offsets_kept);
  EXPECT_FALSE(model.line_delays_kept);
  EXPECT_FALSE(off.report.capture_time_model.computed);
  for (size_t c = 0; c < 5; ++c) {
    EXPECT_EQ(automatic.calibration.cameras[c].Params(),
              off.calibration.cameras[c].Params());
    EXPECT_EQ(automatic.calibration.cam_from_rig[c].translation,
              off.calibration.cam_from_rig[c].translation);
    EXPECT_EQ(automatic.calibration.cam_from_rig[c].rotation.coeffs(),
              off.calibration.cam_from_rig[c].rotation.coeffs());
  }
  EXPECT_EQ(automatic.report.final_rms_px, off.report.final_rms_px);
}

// Framesets further apart than max_frameset_interval_s: auto does not
// estimate and says why, the calibration unchanged; 1 estimates anyway. The
// data are the 15 Hz ring with offsets, its frameset times stretched 10x
// (0.67 s apart): the motion between framesets is then not what the times
// say, as on a real rig whose framesets are seconds apart.
TEST(CaptureTimeModel, FramesetsFarApartAutoSkipsTheModel) {
  SyntheticRigOptions options = TimedRingOptions(30, 40, kRateHz);
  options.max_time_offset_s = 0.05;
  SyntheticRig rig = GenerateSyntheticRig(options);
  SetKnownIntrinsics(&rig);
  for (double& time : rig.dataset.frameset_times_s) time *= 10;
  const RigCalibration start = testing::CalibrationAtTruth(rig);
  FinalBundleAdjustmentOptions ba;
  ba.num_threads = 2;
  CaptureTimeModelOptions model_options;
  RigCalibration calibration = start;
  CaptureTimeModel model;
  std::string error;
  ASSERT_TRUE(AdjustRigWithCaptureTimeModel(model_options, ba, rig.dataset,
                                            &calibration, &model, &error));
  std::cout << model.message << std::endl;
  EXPECT_TRUE(model.computed);
  EXPECT_FALSE(model.time_offsets_kept);
  EXPECT_FALSE(model.line_delays_kept);
  EXPECT_TRUE(model.cameras.empty());
  EXPECT_NE(model.message.find("0.667 s apart"), std::string::npos)
      << model.message;
  for (size_t c = 0; c < 5; ++c) {
    EXPECT_EQ(calibration.cameras[c].Params(), start.cameras[c].Params());
  }
  model_options.time_offsets = CaptureTimeMode::kOn;
  model_options.rolling_shutter = CaptureTimeMode::kOff;
  ASSERT_TRUE(AdjustRigWithCaptureTimeModel(model_options, ba, rig.dataset,
                                            &calibration, &model, &error))
      << error;
  EXPECT_TRUE(model.time_offsets_kept);
  EXPECT_EQ(model.cameras.size(), 5u);
}

// Asked for without frameset times: an error naming the cause; auto: the
// step does not run.
TEST(CaptureTimeModel, WithoutFramesetTimesOnIsAnErrorAutoChangesNothing) {
  SyntheticRigOptions options = TimedRingOptions(12, 40, kRateHz);
  SyntheticRig rig = GenerateSyntheticRig(options);
  SetKnownIntrinsics(&rig);
  rig.dataset.frameset_times_s.clear();
  RigCalibration calibration = testing::CalibrationAtTruth(rig);
  CaptureTimeModelOptions model_options;
  CaptureTimeModel model;
  std::string error;
  EXPECT_TRUE(AdjustRigWithCaptureTimeModel(model_options,
                                            FinalBundleAdjustmentOptions(),
                                            rig.dataset, &calibration, &model,
                                            &error));
  EXPECT_FALSE(model.computed);
  model_options.time_offsets = CaptureTimeMode::kOn;
  EXPECT_FALSE(AdjustRigWithCaptureTimeModel(model_options,
                                             FinalBundleAdjustmentOptions(),
                                             rig.dataset, &calibration, &model,
                                             &error));
  EXPECT_NE(error.find("needs frameset times"), std::string::npos) << error;
  FinalBundleAdjustmentOptions ba = TimeModelOptions();
  EXPECT_FALSE(AdjustRig(ba, rig.dataset, &calibration, nullptr));
}

}  // namespace capture_time_model_test
}  // namespace rig_calibrator
