// COLMAP's refinement switches in the pipeline (intrinsics_refinement.h): a
// held parameter keeps the dataset camera's value bit for bit through every
// method's stages, the others are still estimated, and holding the true
// principal point is at least as accurate as estimating it.
#include "src/rig/intrinsics_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "src/calibration/pipeline.h"
#include "src/evaluation/evaluation.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace intrinsics_refinement_test {

SyntheticRigOptions ShortSequence(int num_framesets, unsigned int seed) {
  SyntheticRigOptions options;
  options.preset = RigPreset::kRing5;
  options.num_framesets = num_framesets;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.3;
  options.min_depth = 2.0;
  options.max_depth = 10.0;
  options.seed = seed;
  return options;
}

PipelineOptions QuietOptions(CalibrationMethod method) {
  PipelineOptions options;
  options.method = method;
  options.print_progress = false;
  return options;
}

// The dataset cameras hold `refinement` at the true values of the held
// parameters (the others stay at their initial guesses).
void HoldAtTruth(const SyntheticRig& truth_rig,
                 const IntrinsicsRefinement& refinement, RigDataset* dataset) {
  for (size_t c = 0; c < dataset->cameras.size(); ++c) {
    RigCamera& camera = dataset->cameras[c];
    camera.refinement = refinement;
    for (const int i : HeldParamIdxs(camera.camera, refinement)) {
      camera.camera.Params(i) = truth_rig.truth.cameras[c].Params(i);
    }
  }
}

TEST(IntrinsicsRefinement, HeldParamIdxsOfOpenCV) {
  colmap::Camera camera;
  camera.InitializeWithName("OPENCV", 500, 640, 480);
  EXPECT_EQ(HeldParamIdxs(camera, {}), std::vector<int>());
  EXPECT_EQ(HeldParamIdxs(camera, {true, false, true}),
            std::vector<int>({2, 3}));
  EXPECT_EQ(HeldParamIdxs(camera, {false, true, false}),
            std::vector<int>({0, 1, 4, 5, 6, 7}));
}

// Every method that estimates intrinsics, each switch alone: the held
// parameters come out exactly as given, the others move.
TEST(IntrinsicsRefinement, HeldParametersStayExactlyAsGiven) {
  const SyntheticRig rig = GenerateSyntheticRig(ShortSequence(12, 3));
  const std::vector<IntrinsicsRefinement> switches = {
      {true, false, true}, {false, true, true}, {true, true, false}};
  for (const CalibrationMethod method :
       {CalibrationMethod::kRadial1D, CalibrationMethod::kRdRa,
        CalibrationMethod::kRd, CalibrationMethod::kKnownRefine}) {
    for (const IntrinsicsRefinement& refinement : switches) {
      SCOPED_TRACE(CalibrationMethodName(method) + " refine f/pp/extra " +
                   std::to_string(refinement.focal_length) +
                   std::to_string(refinement.principal_point) +
                   std::to_string(refinement.extra_params));
      SyntheticRig held = rig;
      if (method == CalibrationMethod::kKnownRefine) SetKnownIntrinsics(&held);
      HoldAtTruth(rig, refinement, &held.dataset);
      // Off the truth, so that "held" cannot pass by estimating the truth.
      for (RigCamera& camera : held.dataset.cameras) {
        for (const int i : HeldParamIdxs(camera.camera, refinement)) {
          camera.camera.Params(i) += i < 4 ? 0.37 : 1e-3;
        }
      }
      RigCalibration calibration;
      PipelineReport report;
      ASSERT_TRUE(CalibrateRig(QuietOptions(method), held.dataset, &calibration,
                               &report))
          << report.error;
      ASSERT_EQ(report.refined_intrinsics.size(), 5u);
      for (size_t c = 0; c < 5; ++c) {
        ASSERT_TRUE(calibration.camera_calibrated[c]);
        const colmap::Camera& given = held.dataset.cameras[c].camera;
        const colmap::Camera& result = calibration.cameras[c];
        const std::vector<int> held_idxs = HeldParamIdxs(given, refinement);
        for (size_t i = 0; i < given.NumParams(); ++i) {
          const bool is_held = std::count(held_idxs.begin(), held_idxs.end(),
                                          static_cast<int>(i)) > 0;
          if (is_held) {
            EXPECT_EQ(result.Params(i), given.Params(i)) << "param " << i;
          } else {
            EXPECT_NE(result.Params(i), given.Params(i)) << "param " << i;
          }
        }
        EXPECT_EQ(report.refined_intrinsics[c].focal_length,
                  refinement.focal_length);
        EXPECT_EQ(report.refined_intrinsics[c].principal_point,
                  refinement.principal_point);
        EXPECT_EQ(report.refined_intrinsics[c].extra_params,
                  refinement.extra_params);
      }
    }
  }
}

// known and known_ra estimate no intrinsics: the report says so whatever
// the switches.
TEST(IntrinsicsRefinement, KnownMethodsReportNothingRefined) {
  SyntheticRig rig = GenerateSyntheticRig(ShortSequence(12, 3));
  SetKnownIntrinsics(&rig);
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kKnownRa),
                           rig.dataset, &calibration, &report));
  for (size_t c = 0; c < 5; ++c) {
    EXPECT_FALSE(report.refined_intrinsics[c].focal_length);
    EXPECT_FALSE(report.refined_intrinsics[c].principal_point);
    EXPECT_FALSE(report.refined_intrinsics[c].extra_params);
    EXPECT_EQ(calibration.cameras[c].Params(),
              rig.dataset.cameras[c].camera.Params());
  }
}

// Per camera: only cam1's principal point is held.
TEST(IntrinsicsRefinement, PerCameraSwitch) {
  SyntheticRig rig = GenerateSyntheticRig(ShortSequence(12, 3));
  rig.dataset.cameras[1].refinement.principal_point = false;
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D),
                           rig.dataset, &calibration, &report));
  for (size_t c = 0; c < 5; ++c) {
    const bool same = calibration.cameras[c].PrincipalPointX() ==
                      rig.dataset.cameras[c].camera.PrincipalPointX();
    EXPECT_EQ(same, c == 1) << "camera " << c;
  }
}

// Short sequences (5 and 8 framesets, 0.5 px noise, 30 % wrong
// correspondences), 4 seeds each: with the true principal point given and
// held, the worst camera of the rig is at least as accurate as with the
// principal point estimated (the measured numbers are printed).
TEST(IntrinsicsRefinement, HeldTruePrincipalPointIsAtLeastAsAccurate) {
  double free_rotation = 0, held_rotation = 0, free_center = 0, held_center = 0,
         free_projection = 0, held_projection = 0;
  int num_runs = 0;
  for (const int num_framesets : {5, 8}) {
    for (unsigned int seed = 1; seed <= 4; ++seed) {
      const SyntheticRig rig =
          GenerateSyntheticRig(ShortSequence(num_framesets, seed));
      SyntheticRig held = rig;
      HoldAtTruth(rig, {true, false, true}, &held.dataset);
      RigCalibration free_calibration, held_calibration;
      PipelineReport report;
      if (!CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D), rig.dataset,
                        &free_calibration, &report)) {
        continue;
      }
      ASSERT_TRUE(CalibrateRig(QuietOptions(CalibrationMethod::kRadial1D),
                               held.dataset, &held_calibration, &report))
          << report.error;
      const auto worst = [&rig](const RigCalibration& calibration,
                                double* rotation, double* center,
                                double* projection) {
        const CalibrationError error = CompareCalibrations(
            rig.truth.cameras, rig.truth.cam_from_rig, calibration.cameras,
            calibration.cam_from_rig, /*align_scale=*/false);
        double r = 0, t = 0, p = 0;
        for (const CameraError& camera : error.cameras) {
          r = std::max(r, camera.rotation_deg);
          t = std::max(t, camera.center_error);
          p = std::max(p, camera.mean_projection_diff_px);
        }
        *rotation += r;
        *center += t;
        *projection += p;
      };
      worst(free_calibration, &free_rotation, &free_center, &free_projection);
      worst(held_calibration, &held_rotation, &held_center, &held_projection);
      ++num_runs;
    }
  }
  ASSERT_GE(num_runs, 6);
  std::cout << "mean over " << num_runs
            << " short sequences of the worst camera, free -> held true "
               "principal point: rotation "
            << free_rotation / num_runs << " -> " << held_rotation / num_runs
            << " deg, center " << 1000 * free_center / num_runs << " -> "
            << 1000 * held_center / num_runs << " mm, mean projection "
            << free_projection / num_runs << " -> "
            << held_projection / num_runs << " px" << std::endl;
  EXPECT_LE(held_rotation, free_rotation);
  EXPECT_LE(held_center, free_center);
  EXPECT_LE(held_projection, free_projection);
}

}  // namespace intrinsics_refinement_test
}  // namespace rig_calibrator
