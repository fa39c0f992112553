#include "src/calibration/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "src/evaluation/evaluation.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace pipeline_test {

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

// CalibrateRig with `method`, asserted to succeed.
struct PipelineRun {
  RigCalibration calibration;
  PipelineReport report;
};
PipelineRun CalibrateOrFail(const PipelineOptions& options,
                            const RigDataset& dataset) {
  PipelineRun run;
  EXPECT_TRUE(CalibrateRig(options, dataset, &run.calibration, &run.report))
      << run.report.error;
  return run;
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

TEST(Pipeline, DefaultMethodMeetsAccuracyTargets) {
  for (const RigPreset preset :
       {RigPreset::kRing5, RigPreset::kFisheyeHelmet5}) {
    SCOPED_TRACE(RigPresetName(preset));
    const SyntheticRig rig = GenerateSyntheticRig(HardScenario(preset));
    const PipelineRun run = CalibrateOrFail(
        QuietOptions(CalibrationMethod::kRadial1D), rig.dataset);
    EXPECT_EQ(run.report.used_method, CalibrationMethod::kRadial1D);
    EXPECT_FALSE(run.report.HasErrors());
    ExpectAccurate(rig, run.calibration, 0.05, 0.002, 0.2, 1.0);
    EXPECT_LT(run.report.final_rms_px, 1.0);
  }
}

TEST(Pipeline, CarSurroundWithMixedModels) {
  const SyntheticRig rig =
      GenerateSyntheticRig(HardScenario(RigPreset::kCarSurround4));
  const PipelineRun run =
      CalibrateOrFail(QuietOptions(CalibrationMethod::kRadial1D), rig.dataset);
  ExpectAccurate(rig, run.calibration, 0.1, 0.005, 0.3, 1.5);
}

TEST(Pipeline, StereoPairIsDiagnosedAndCalibratedThroughFallback) {
  SyntheticRigOptions options = HardScenario(RigPreset::kStereoPair);
  options.outlier_ratio = 0.2;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  const PipelineRun run =
      CalibrateOrFail(QuietOptions(CalibrationMethod::kRadial1D), rig.dataset);
  EXPECT_TRUE(HasDiagnostic(run.report, "parallel_principal_axes"));
  EXPECT_EQ(run.report.used_method, CalibrationMethod::kRdRa);
  ExpectAccurate(rig, run.calibration, 0.1, 0.005, 0.5, 2.0);
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

TEST(Pipeline, MethodNamesRoundTrip) {
  for (const CalibrationMethod method :
       {CalibrationMethod::kKnown, CalibrationMethod::kKnownRefine,
        CalibrationMethod::kKnownRa, CalibrationMethod::kRd,
        CalibrationMethod::kRdRa, CalibrationMethod::kRadial1D}) {
    CalibrationMethod parsed = CalibrationMethod::kRadial1D;
    ASSERT_TRUE(
        CalibrationMethodFromName(CalibrationMethodName(method), &parsed));
    EXPECT_EQ(parsed, method);
  }
  CalibrationMethod parsed;
  EXPECT_FALSE(CalibrationMethodFromName("kalibr", &parsed));
  EXPECT_EQ(CalibrationMethodName(CalibrationMethod::kKnownRa), "known_ra");
}

// known and known_ra hold the given intrinsics (bit for bit: the final BA
// does not touch them); known_refine refines them, and they move off the
// truth by the noise's amount.
TEST(Pipeline, KnownIntrinsicsAreKeptByKnownAndRefinedByKnownRefine) {
  SyntheticRig rig = GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  SetKnownIntrinsics(&rig);
  for (const CalibrationMethod method :
       {CalibrationMethod::kKnown, CalibrationMethod::kKnownRefine,
        CalibrationMethod::kKnownRa}) {
    SCOPED_TRACE(CalibrationMethodName(method));
    const PipelineRun run = CalibrateOrFail(QuietOptions(method), rig.dataset);
    for (size_t c = 0; c < rig.truth.cameras.size(); ++c) {
      if (method == CalibrationMethod::kKnownRefine) {
        EXPECT_NE(run.calibration.cameras[c].Params(),
                  rig.truth.cameras[c].Params());
      } else {
        EXPECT_EQ(run.calibration.cameras[c].Params(),
                  rig.truth.cameras[c].Params());
      }
    }
    ExpectAccurate(rig, run.calibration, 0.05, 0.002, 0.2, 1.0);
  }
}

TEST(Pipeline, PerImageIntrinsicsMethodsCalibrateTheRing) {
  const SyntheticRig rig =
      GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  for (const CalibrationMethod method :
       {CalibrationMethod::kRd, CalibrationMethod::kRdRa}) {
    SCOPED_TRACE(CalibrationMethodName(method));
    const PipelineRun run = CalibrateOrFail(QuietOptions(method), rig.dataset);
    ExpectAccurate(rig, run.calibration, 0.1, 0.005, 0.5, 2.0);
  }
}

// The paper's baselines rd, known and known_refine take the rig from a
// complete frameset (Heng et al.); without one they fail and name the robust
// alternative, which calibrates the same data.
TEST(Pipeline, CompleteFramesetMethodsNeedACompleteFrameset) {
  SyntheticRigOptions options = HardScenario(RigPreset::kRing5);
  options.num_framesets = 12;
  SyntheticRig rig = GenerateSyntheticRig(options);
  SetKnownIntrinsics(&rig);
  // Drop one camera's image from every frameset: no frameset is complete.
  std::vector<RigImage> kept;
  for (const RigImage& image : rig.dataset.images) {
    if (image.camera_index != image.frameset_index % 5) kept.push_back(image);
  }
  rig.dataset.images = kept;
  const std::vector<std::pair<CalibrationMethod, CalibrationMethod>>
      alternatives = {
          {CalibrationMethod::kRd, CalibrationMethod::kRdRa},
          {CalibrationMethod::kKnown, CalibrationMethod::kKnownRa},
          {CalibrationMethod::kKnownRefine, CalibrationMethod::kKnownRa}};
  for (const auto& [method, alternative] : alternatives) {
    SCOPED_TRACE(CalibrationMethodName(method));
    RigCalibration calibration;
    PipelineReport report;
    EXPECT_FALSE(
        CalibrateRig(QuietOptions(method), rig.dataset, &calibration, &report));
    EXPECT_NE(report.error.find("every camera was localized"),
              std::string::npos)
        << report.error;
    EXPECT_NE(report.error.find("use " + CalibrationMethodName(alternative)),
              std::string::npos)
        << report.error;
    const PipelineRun run =
        CalibrateOrFail(QuietOptions(alternative), rig.dataset);
    ExpectAccurate(rig, run.calibration, 0.1, 0.005, 0.5, 2.0);
  }
}

// known takes the rig from the best complete frameset: before the final BA
// its extrinsics are exactly those of that frameset's single-image poses,
// where known_ra's robust initialization averages over all framesets.
TEST(Pipeline, KnownStartsFromTheBestCompleteFrameset) {
  SyntheticRig rig = GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  SetKnownIntrinsics(&rig);
  const PipelineRun known =
      CalibrateOrFail(QuietOptions(CalibrationMethod::kKnown), rig.dataset);
  const PipelineRun known_ra =
      CalibrateOrFail(QuietOptions(CalibrationMethod::kKnownRa), rig.dataset);
  // The frameset whose single-image poses give known's initial rig.
  int matching_framesets = 0;
  for (size_t j = 0; j < rig.dataset.frameset_names.size(); ++j) {
    std::vector<Rigid3d> cam_from_world(rig.truth.cameras.size());
    int num_localized = 0;
    for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
      const ImageResult& image = known.calibration.images[i];
      if (rig.dataset.images[i].frameset_index != static_cast<int>(j) ||
          !image.localized) {
        continue;
      }
      cam_from_world[rig.dataset.images[i].camera_index] =
          *image.single_image_cam_from_world;
      ++num_localized;
    }
    if (num_localized != static_cast<int>(rig.truth.cameras.size())) continue;
    bool matches = true;
    for (size_t c = 0; c < cam_from_world.size(); ++c) {
      const Rigid3d expected = cam_from_world[c] * cam_from_world[0].Inverse();
      matches = matches && (expected.translation -
                            known.report.initial_cam_from_rig[c].translation)
                                   .norm() < 1e-12;
    }
    matching_framesets += matches;
  }
  EXPECT_EQ(matching_framesets, 1);
  const std::vector<Rigid3d>& initial_ra = known_ra.report.initial_cam_from_rig;
  double difference = 0;
  for (size_t c = 0; c < initial_ra.size(); ++c) {
    difference =
        std::max(difference, (initial_ra[c].translation -
                              known.report.initial_cam_from_rig[c].translation)
                                 .norm());
  }
  EXPECT_GT(difference, 1e-6);
}

TEST(Pipeline, CameraThatNeverLocalizesIsReportedOthersCalibrated) {
  SyntheticRig rig = GenerateSyntheticRig(HardScenario(RigPreset::kRing5));
  for (RigImage& image : rig.dataset.images) {
    if (image.camera_index == 3) image.correspondences.resize(3);
  }
  const PipelineRun run =
      CalibrateOrFail(QuietOptions(CalibrationMethod::kRadial1D), rig.dataset);
  const RigCalibration& calibration = run.calibration;
  const PipelineReport& report = run.report;
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

// Every output, not only a summary number: all intrinsics, every
// cam_from_rig and rig pose, the inlier masks and the initial rig.
TEST(Pipeline, ResultDoesNotDependOnThreadCount) {
  SyntheticRigOptions options = HardScenario(RigPreset::kRing5);
  options.num_framesets = 10;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  PipelineOptions pipeline = QuietOptions(CalibrationMethod::kRadial1D);
  pipeline.num_threads = 1;
  const PipelineRun one = CalibrateOrFail(pipeline, rig.dataset);
  pipeline.num_threads = 2;
  const PipelineRun two = CalibrateOrFail(pipeline, rig.dataset);
  const RigCalibration& a = one.calibration;
  const RigCalibration& b = two.calibration;
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  EXPECT_EQ(a.camera_calibrated, b.camera_calibrated);
  // Ceres sums the residual blocks in another order on two threads: equal to
  // rounding of the solve.
  const auto expect_pose_near = [](const Rigid3d& x, const Rigid3d& y) {
    EXPECT_LT(RotationDifferenceDeg(x.rotation, y.rotation), 1e-7);
    EXPECT_LT((x.translation - y.translation).norm(), 1e-8);
  };
  for (size_t c = 0; c < a.cameras.size(); ++c) {
    SCOPED_TRACE("camera " + std::to_string(c));
    ASSERT_EQ(a.cameras[c].NumParams(), b.cameras[c].NumParams());
    for (size_t p = 0; p < a.cameras[c].NumParams(); ++p) {
      EXPECT_NEAR(a.cameras[c].Params()[p], b.cameras[c].Params()[p],
                  1e-6 * std::max(1.0, std::abs(a.cameras[c].Params()[p])));
    }
    expect_pose_near(a.cam_from_rig[c], b.cam_from_rig[c]);
    expect_pose_near(one.report.initial_cam_from_rig[c],
                     two.report.initial_cam_from_rig[c]);
  }
  ASSERT_EQ(a.rig_from_world.size(), b.rig_from_world.size());
  for (size_t j = 0; j < a.rig_from_world.size(); ++j) {
    ASSERT_EQ(a.rig_from_world[j].has_value(), b.rig_from_world[j].has_value());
    if (a.rig_from_world[j]) {
      expect_pose_near(*a.rig_from_world[j], *b.rig_from_world[j]);
    }
  }
  for (size_t i = 0; i < a.images.size(); ++i) {
    EXPECT_EQ(a.images[i].localized, b.images[i].localized);
    EXPECT_EQ(a.images[i].used, b.images[i].used);
    EXPECT_EQ(a.images[i].inlier_mask, b.images[i].inlier_mask) << i;
  }
  EXPECT_NEAR(one.report.final_rms_px, two.report.final_rms_px, 1e-9);
}

TEST(Pipeline, InvalidDatasetIsRejected) {
  RigDataset dataset;
  RigCalibration calibration;
  PipelineReport report;
  EXPECT_FALSE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D), dataset,
                            &calibration, &report));
  EXPECT_NE(report.error.find("at least two cameras"), std::string::npos);
}

}  // namespace pipeline_test
}  // namespace rig_calibrator
