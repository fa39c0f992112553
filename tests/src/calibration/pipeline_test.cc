#include "src/calibration/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "src/evaluation/evaluation.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace {

PipelineOptions QuietOptions(CalibrationMethod method) {
  PipelineOptions options;
  options.method = method;
  options.print_progress = false;
  return options;
}

// The accuracy scenario: 30 framesets, 0.5 px noise, 30% outliers,
// 10% of the images missing, map points 2-10 m away.
SyntheticRigOptions HardScenario(RigPreset preset) {
  SyntheticRigOptions options;
  options.preset = preset;
  options.num_framesets = 30;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.3;
  options.missing_image_ratio = 0.1;
  options.min_depth = 2.0;
  options.max_depth = 10.0;
  options.seed = 7;
  return options;
}

CalibrationError Errors(const SyntheticRig& rig,
                        const RigCalibration& calibration) {
  return CompareCalibrations(rig.truth.cameras, rig.truth.cam_from_rig,
                             calibration.cameras, calibration.cam_from_rig,
                             /*align_scale=*/false);
}

bool HasDiagnostic(const PipelineReport& report, const std::string& code) {
  return std::any_of(
      report.diagnostics.begin(), report.diagnostics.end(),
      [&](const Diagnostic& diagnostic) { return diagnostic.code == code; });
}

void ExpectAccurate(const SyntheticRig& rig, const RigCalibration& calibration,
                    double max_rotation_deg, double max_center_m,
                    double max_focal_percent, double max_principal_point_px) {
  const CalibrationError error = Errors(rig, calibration);
  ASSERT_EQ(error.cameras.size(), rig.truth.cameras.size());
  for (size_t c = 0; c < error.cameras.size(); ++c) {
    SCOPED_TRACE("camera " + rig.truth.camera_names[c]);
    EXPECT_TRUE(calibration.camera_calibrated[c]);
    EXPECT_LT(error.cameras[c].rotation_deg, max_rotation_deg);
    EXPECT_LT(error.cameras[c].center_error, max_center_m);
    EXPECT_LT(error.cameras[c].focal_error_percent, max_focal_percent);
    EXPECT_LT(error.cameras[c].principal_point_error_px,
              max_principal_point_px);
  }
}

TEST(Pipeline, Ring5DefaultMethodMeetsAccuracyTargets) {
  const SyntheticRig rig =
      GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D),
                           rig.dataset, &calibration, &report))
      << report.error;
  EXPECT_EQ(report.used_method, CalibrationMethod::kRadial1D);
  EXPECT_FALSE(report.HasErrors());
  ExpectAccurate(rig, calibration, 0.05, 0.002, 0.2, 1.0);
  EXPECT_LT(report.final_rms_px, 1.0);
}

TEST(Pipeline, FisheyeHelmetDefaultMethodMeetsAccuracyTargets) {
  const SyntheticRig rig =
      GenerateSyntheticRig(HardScenario(RigPreset::kFisheyeHelmet5));
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D),
                           rig.dataset, &calibration, &report))
      << report.error;
  EXPECT_EQ(report.used_method, CalibrationMethod::kRadial1D);
  ExpectAccurate(rig, calibration, 0.05, 0.002, 0.2, 1.0);
}

TEST(Pipeline, CarSurroundWithMixedModels) {
  const SyntheticRig rig =
      GenerateSyntheticRig(HardScenario(RigPreset::kCarSurround4));
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D),
                           rig.dataset, &calibration, &report))
      << report.error;
  ExpectAccurate(rig, calibration, 0.1, 0.005, 0.3, 1.5);
}

TEST(Pipeline, StereoPairIsDiagnosedAndCalibratedThroughFallback) {
  SyntheticRigOptions options = HardScenario(RigPreset::kStereoPair);
  options.outlier_ratio = 0.2;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D),
                           rig.dataset, &calibration, &report))
      << report.error;
  EXPECT_TRUE(HasDiagnostic(report, "parallel_principal_axes"));
  EXPECT_EQ(report.used_method, CalibrationMethod::kRdRa);
  ExpectAccurate(rig, calibration, 0.1, 0.005, 0.5, 2.0);
}

TEST(Pipeline, StereoPairWithoutFallbackFailsWithExplanation) {
  const SyntheticRig rig =
      GenerateSyntheticRig(HardScenario(RigPreset::kStereoPair));
  PipelineOptions options = QuietOptions(CalibrationMethod::kRadial1D);
  options.fallback_on_parallel_axes = false;
  RigCalibration calibration;
  PipelineReport report;
  EXPECT_FALSE(CalibrateRig(options, rig.dataset, &calibration, &report));
  EXPECT_NE(report.error.find("rd_ra"), std::string::npos) << report.error;
}

TEST(Pipeline, KnownIntrinsicsAreKeptByKnownAndRefinedByKnownRefine) {
  SyntheticRig rig = GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  SetKnownIntrinsics(&rig);
  for (const CalibrationMethod method :
       {CalibrationMethod::kKnown, CalibrationMethod::kKnownRefine}) {
    SCOPED_TRACE(CalibrationMethodName(method));
    RigCalibration calibration;
    PipelineReport report;
    ASSERT_TRUE(
        CalibrateRig(QuietOptions(method), rig.dataset, &calibration, &report))
        << report.error;
    if (method == CalibrationMethod::kKnown) {
      for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
        EXPECT_EQ(calibration.cameras[c].Params(),
                  rig.truth.cameras[c].Params());
      }
    }
    ExpectAccurate(rig, calibration, 0.05, 0.002, 0.2, 1.0);
  }
}

TEST(Pipeline, PerImageIntrinsicsMethodsCalibrateTheRing) {
  const SyntheticRig rig =
      GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  for (const CalibrationMethod method :
       {CalibrationMethod::kRd, CalibrationMethod::kRdRa}) {
    SCOPED_TRACE(CalibrationMethodName(method));
    RigCalibration calibration;
    PipelineReport report;
    ASSERT_TRUE(
        CalibrateRig(QuietOptions(method), rig.dataset, &calibration, &report))
        << report.error;
    ExpectAccurate(rig, calibration, 0.1, 0.005, 0.5, 2.0);
  }
}

TEST(Pipeline, RdWithoutCompleteFramesetFailsWithExplanation) {
  SyntheticRigOptions options = HardScenario(RigPreset::kRing5);
  options.num_framesets = 6;
  SyntheticRig rig = GenerateSyntheticRig(options);
  // Drop one camera's image from every frameset: no frameset is complete.
  std::vector<RigImage> kept;
  for (const RigImage& image : rig.dataset.images) {
    if (image.camera_index != image.frameset_index % 5) kept.push_back(image);
  }
  rig.dataset.images = kept;
  RigCalibration calibration;
  PipelineReport report;
  EXPECT_FALSE(CalibrateRig(QuietOptions(CalibrationMethod::kRd), rig.dataset,
                            &calibration, &report));
  EXPECT_NE(report.error.find("rd_ra or 1dr"), std::string::npos)
      << report.error;
}

TEST(Pipeline, CameraThatNeverLocalizesIsReportedOthersCalibrated) {
  SyntheticRig rig = GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  for (RigImage& image : rig.dataset.images) {
    if (image.camera_index == 3) image.correspondences.resize(3);
  }
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D),
                           rig.dataset, &calibration, &report))
      << report.error;
  EXPECT_TRUE(HasDiagnostic(report, "camera_not_localized"));
  EXPECT_TRUE(HasDiagnostic(report, "camera_not_calibrated"));
  EXPECT_FALSE(calibration.camera_calibrated[3]);
  // Camera 3 has no cam_from_rig: align the rigs by the reference camera
  // only, not by all cameras.
  CompareOptions compare;
  compare.alignment = RigAlignment::kReferenceCamera;
  const CalibrationError error = CompareCalibrations(
      rig.truth.cameras, rig.truth.cam_from_rig, calibration.cameras,
      calibration.cam_from_rig, compare);
  for (const int c : {1, 2, 4}) {
    EXPECT_TRUE(calibration.camera_calibrated[c]);
    EXPECT_LT(error.cameras[c].rotation_deg, 0.05);
  }
}

TEST(Pipeline, ResultDoesNotDependOnThreadCount) {
  SyntheticRigOptions options = HardScenario(RigPreset::kRing5);
  options.num_framesets = 10;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  RigCalibration one_thread, two_threads;
  PipelineReport report;
  PipelineOptions pipeline = QuietOptions(CalibrationMethod::kRadial1D);
  pipeline.num_threads = 1;
  ASSERT_TRUE(CalibrateRig(pipeline, rig.dataset, &one_thread, &report));
  pipeline.num_threads = 2;
  ASSERT_TRUE(CalibrateRig(pipeline, rig.dataset, &two_threads, &report));
  for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
    EXPECT_NEAR(one_thread.cameras[c].FocalLengthX(),
                two_threads.cameras[c].FocalLengthX(), 1e-6);
  }
}

TEST(Pipeline, InvalidDatasetIsRejected) {
  RigDataset dataset;
  RigCalibration calibration;
  PipelineReport report;
  EXPECT_FALSE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D), dataset,
                            &calibration, &report));
  EXPECT_NE(report.error.find("at least two cameras"), std::string::npos);
}

}  // namespace
}  // namespace rig_calibrator
